// Internal to the scene module: particle counts and placement, shared by
// validation (which must refuse huge scenes before anything allocates, and
// particles outside the box) and by make_particles.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "swirl/scene/scene.hpp"

namespace swirl::scene::detail {

// The most particles a scene may make: 2^31.
inline constexpr std::uint64_t kMaxParticles = std::uint64_t{1} << 31;

// Stands for "too many to count" in the saturating counts below.
inline constexpr std::uint64_t kSaturated = std::numeric_limits<std::uint64_t>::max();

// Lattice points along x, y and z: floor(extent / spacing) each, with a relative
// tolerance of 1e-12 so that 0.3 / 0.1 counts as 3. kSaturated when not finite or
// beyond 2^53.
std::array<std::uint64_t, 3> lattice_counts(const LatticeSource& source);

// Particles one source makes, saturating at kSaturated.
std::uint64_t source_count(const ParticleSource& source);

// Boundary particles of one obstacle (obstacle_points() would make), saturating.
std::uint64_t obstacle_count(const ObstacleSource& source);

// The walls' boundary particles (box.walls = "particles"; 0 otherwise), and the box they sample.
std::uint64_t wall_count(const Scene& scene);
Box<double> grown_box(const Scene& scene);

// x moved by `by`, adding only the non-zero components: x + 0.0 turns a −0.0
// into +0.0, and a snapshot read back must give its particles bit for bit.
inline Vec3d moved(Vec3d x, const Vec3d& by) {
  for (int axis = 0; axis < 3; ++axis)
    if (by[axis] != 0) x[axis] += by[axis];
  return x;
}

// a + b and a * b, saturating at kSaturated.
constexpr std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) { return a > kSaturated - b ? kSaturated : a + b; }
constexpr std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) {
  return a != 0 && b > kSaturated / a ? kSaturated : a * b;
}

}  // namespace swirl::scene::detail
