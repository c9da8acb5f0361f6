// MovingBoundaries: the obstacles whose boundary particles follow a
// prescribed rigid motion (boundary/rigid_motion.hpp). Their particles are
// not integrated: before every force evaluation at time t the simulation
// (sim/simulation.hpp) sets each one's position and velocity to the motion's
// value for its rest position,
//   x_b = c + R(t)(x0_b − c) + s(t),   v_b = ω(t) × R(t)(x0_b − c) + ṡ(t),
// so that the order's sort (and its skin check) sees where they are, and the
// SPH passes that read a boundary particle's velocity (DFSPH's Dρ/Dt, the
// viscosity, the walls' reaction) see the wall's own motion.
//
// A moving obstacle is known by its particles' ids, [first_id, first_id +
// rest.size()) (scene::obstacle_ids(): ids travel with particles through every
// reorder and checkpoint), and its rest positions x0 are kept here in double,
// indexed by id − first_id, made from the scene as the particles were. So the
// motion needs no particle field and no checkpoint state: a resumed run
// rebuilds this table from the scene and places every moving particle exactly
// where the uninterrupted run does.
//
// Determinism: each particle's values depend on its id and t alone.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "swirl/boundary/rigid_motion.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::boundary {

// One moving obstacle: its particles' ids and rest positions (m), and its motion.
struct MovingObstacle {
  std::uint64_t first_id = 0;
  std::vector<Vec3d> rest;  // x0 of particle id first_id + k at [k]
  RigidMotion motion;
};

class MovingBoundaries {
 public:
  // Obstacles with disjoint id ranges (any order; kept sorted by first id).
  explicit MovingBoundaries(std::vector<MovingObstacle> obstacles) : obstacles_(std::move(obstacles)) {
    std::sort(obstacles_.begin(), obstacles_.end(),
              [](const MovingObstacle& a, const MovingObstacle& b) { return a.first_id < b.first_id; });
    for (std::size_t k = 1; k < obstacles_.size(); ++k)
      if (obstacles_[k].first_id < obstacles_[k - 1].first_id + obstacles_[k - 1].rest.size())
        throw std::invalid_argument("MovingBoundaries: two obstacles share particle ids");
  }

  bool empty() const { return obstacles_.empty(); }
  const std::vector<MovingObstacle>& obstacles() const { return obstacles_; }

  // Sets x and v of every moving obstacle's particles in p to their values at time t.
  template <class Real>
  void apply(ParticleSet<Real>& p, double t, std::size_t block_size) const {
    if (obstacles_.empty()) return;
    std::vector<RigidMotion::Pose> poses;
    poses.reserve(obstacles_.size());
    for (const auto& o : obstacles_) poses.push_back(o.motion.pose(t));
    parallel::for_blocks_pinned("move_boundaries", p.size(), block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        const std::uint64_t id = p.id[i];
        const auto it = std::upper_bound(obstacles_.begin(), obstacles_.end(), id,
                                         [](std::uint64_t v, const MovingObstacle& o) { return v < o.first_id; });
        if (it == obstacles_.begin()) continue;
        const MovingObstacle& o = *(it - 1);
        if (id - o.first_id >= o.rest.size()) continue;
        const RigidMotion::Pose& pose = poses[static_cast<std::size_t>(it - 1 - obstacles_.begin())];
        const Vec3d& x0 = o.rest[id - o.first_id];
        p.position.set(i, pose.position(x0).template cast<Real>());
        p.velocity.set(i, pose.velocity(x0).template cast<Real>());
      }
    });
  }

 private:
  std::vector<MovingObstacle> obstacles_;
};

}  // namespace swirl::boundary
