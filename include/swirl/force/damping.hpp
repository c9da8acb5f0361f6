// Damping: a linear drag a = −γ·v on every particle (γ in 1/s, ≥ 0), scene
// key forces.damping. It removes kinetic energy at the rate 2γK, so a system
// settles into its equilibrium (a self-gravitating fluid sphere into
// hydrostatic balance, a fluid at rest in a tank) in a few 1/γ; it is not
// physical dissipation and belongs to set-up runs, not to the flow studied.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "swirl/force/solver.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl {

template <class Real>
class Damping final : public Solver<Real> {
 public:
  explicit Damping(double rate) : rate_(rate) {
    if (!(rate >= 0) || !std::isfinite(rate)) throw std::invalid_argument("damping rate must be finite and >= 0");
  }
  std::string_view name() const override { return "damping"; }

  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
    const Real gamma = Real(rate_);
    parallel::for_blocks_pinned("damping", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (int axis = 0; axis < 3; ++axis) {
        Real* a = p.acceleration[axis].data();
        const Real* v = p.velocity[axis].data();
#pragma omp simd
        for (std::size_t i = b; i < e; ++i) a[i] -= gamma * v[i];
      }
    });
  }

  // A drag of rate γ needs Δt·γ small for the explicit step to stay a drag.
  void add_limits(const StepScan& /*scan*/, std::size_t /*n*/, std::vector<StepLimit>& out) const override {
    if (rate_ > 0) out.push_back({"damping", 0.5 / rate_, kNoParticle, rate_, "γ"});
  }
  LimitText explain(const StepLimit& l, std::string_view /*particle*/) const override {
    return {fmt::format("the damping condition 0.5/γ = 0.5/{:.3g} = {:.6g}", rate_, l.dt), "or a smaller forces.damping"};
  }
  bool conserves_energy() const override { return false; }

  double rate() const { return rate_; }

 private:
  double rate_;
};

}  // namespace swirl
