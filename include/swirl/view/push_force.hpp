// PushForce<Real>: the live view's mouse as a force (view/live_run.hpp).
//
// While the page holds the push on, every particle within radius R of the
// point p is pulled toward the drag's velocity u:
//   a_i += s · (u − v_i) · (1 − |x_i − p| / R)
// s the strength (1/s): a velocity relaxation with a soft edge, so the fluid
// under the pointer moves with it and a fast drag cannot fling it further than
// the pointer went. The state is set from the server's thread (set()) and read
// once per evaluation under a lock, so an evaluation sees one consistent push.
// It adds energy: conserves_energy() is false (no energy check in a live run).
#pragma once

#include <cmath>
#include <mutex>
#include <string_view>

#include "swirl/force/solver.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/view/wire.hpp"

namespace swirl::view {

template <class Real>
class PushForce final : public Solver<Real> {
 public:
  std::string_view name() const override { return "push"; }
  bool conserves_energy() const override { return false; }

  void set(const control::Push& push) {
    std::lock_guard lock(mutex_);
    push_ = push;
  }
  control::Push get() const {
    std::lock_guard lock(mutex_);
    return push_;
  }

  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
    const control::Push push = get();
    if (!push.on || !(push.strength > 0)) return;
    const Real px = Real(push.point.x), py = Real(push.point.y), pz = Real(push.point.z);
    const Real ux = Real(push.velocity.x), uy = Real(push.velocity.y), uz = Real(push.velocity.z);
    const Real inv_r = Real(1) / Real(push.radius), s = Real(push.strength);
    parallel::for_blocks("push_force", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        if (!ctx.active.contains(i)) continue;
        const Real dx = p.position.x[i] - px, dy = p.position.y[i] - py, dz = p.position.z[i] - pz;
        const Real w = Real(1) - std::sqrt(dx * dx + dy * dy + dz * dz) * inv_r;
        if (!(w > 0)) continue;
        p.acceleration.x[i] += s * w * (ux - p.velocity.x[i]);
        p.acceleration.y[i] += s * w * (uy - p.velocity.y[i]);
        p.acceleration.z[i] += s * w * (uz - p.velocity.z[i]);
      }
    });
  }

 private:
  mutable std::mutex mutex_;
  control::Push push_;
};

}  // namespace swirl::view
