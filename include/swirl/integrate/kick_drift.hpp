// KickDriftStepper<Real>: the two explicit second-order methods, with the
// thesis's two-pass box, behind the Stepper seam (integrate/stepper.hpp).
//
// Velocity Verlet, the thesis's integrator (section 4.4, eq. 4.1 and 4.2):
//   drift   x ← x + v·Δt + ½·a·Δt², a_prev ← a                   (4.2)
//           box pass two for particles outside before and after
//   forces  a ← F(x)
//           box pass one: outward normal velocity ← −e·v_n
//   kick    v ← v + ½·(a_prev + a)·Δt                             (4.1)
// This is Algorithm 1's cycle (forces, pass one, velocity, position, pass two)
// with the loop boundary after the velocity update, so that x, v, a and every
// solver field belong to one time between steps, and the first step does not
// add a₀·Δt to v₀ (exact for a constant acceleration).
//
// Leapfrog kick–drift–kick (the N-body codes' usual form):
//   kick    v ← v + ½·a·Δt;  drift  x ← x + v·Δt  (+ box pass two)
//   forces  a ← F(x)         (+ box pass one)
//   kick    v ← v + ½·a·Δt
// The same positions as velocity Verlet in exact arithmetic, without the
// a_prev field (three fewer arrays to store and reorder); different rounding.
//
// The scan of the new state (force/step_scan.hpp) is fused into the last kick.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "swirl/boundary/box_collision.hpp"
#include "swirl/integrate/stepper.hpp"
#include "swirl/integrate/velocity_verlet.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::integrate {

enum class Method { VelocityVerlet, LeapfrogKDK };

template <class Real>
class KickDriftStepper final : public Stepper<Real> {
 public:
  explicit KickDriftStepper(Method method = Method::VelocityVerlet,
                            std::optional<boundary::BoxCollision<Real>> box = std::nullopt)
      : method_(method), box_(std::move(box)) {}

  std::string_view name() const override {
    return method_ == Method::VelocityVerlet ? "velocity_verlet" : "leapfrog";
  }

  const std::optional<boundary::BoxCollision<Real>>& box() const { return box_; }

  void start(ParticleSet<Real>& p, Forces& forces, double time, std::size_t /*block_size*/) override {
    forces.evaluate(time);
    if (method_ == Method::VelocityVerlet)
      for (int axis = 0; axis < 3; ++axis) p.acceleration_prev[axis] = p.acceleration[axis];
  }

  StepOutcome advance(ParticleSet<Real>& p, Forces& forces, const StepRequest& r) override {
    const Real dt = Real(r.dt);
    StepOutcome out;
    {
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "integrate");
      outside_before_.resize(p.size());
      out.escape = parallel::reduce_blocks_pinned(
          "drift", p.size(), r.block_size, Escape{},
          [&](std::size_t b, std::size_t e) { return drift_block(p, b, e, dt, r.escape_length); },
          [](const Escape& x, const Escape& y) { return y.excess > x.excess ? y : x; });
    }
    forces.evaluate(r.t_next);
    std::optional<ScopedPhase> phase;
    if (r.timers) phase.emplace(*r.timers, "integrate");
    out.scan = parallel::reduce_blocks_pinned(
        "kick", p.size(), r.block_size, StepScan{},
        [&](std::size_t b, std::size_t e) { return kick_block(p, b, e, dt, r); }, &StepScan::combine);
    return out;
  }

 private:
  Escape drift_block(ParticleSet<Real>& p, std::size_t begin, std::size_t end, Real dt, double escape_length) {
    if (method_ == Method::LeapfrogKDK) half_kick(p, begin, end, dt);
    if (!box_) {
      move(p, begin, end, dt);
      return {};
    }
    // Pass two needs to know who was outside before the position update.
    std::uint8_t* was_outside = outside_before_.data();
    for (std::size_t i = begin; i < end; ++i) was_outside[i] = box_->outside(p, i) ? 1 : 0;
    move(p, begin, end, dt);
    for (std::size_t i = begin; i < end; ++i)
      if (was_outside[i]) box_->project_if_outside(p, i);
    if (!(escape_length > 0)) return {};
    // The block's largest distance outside (vectorised); particles only when it is too far.
    auto outside_by = [&](std::size_t i) {
      Real excess = 0;
      for (int axis = 0; axis < 3; ++axis) {
        const Real x = p.position[axis][i];
        excess = std::max(excess, std::max(box_->box.lo[axis] - x, x - box_->box.hi[axis]));
      }
      return excess;
    };
    Real furthest = 0;
#pragma omp simd reduction(max : furthest)
    for (std::size_t i = begin; i < end; ++i) furthest = std::max(furthest, outside_by(i));
    if (!(double(furthest) > escape_length)) return {};
    for (std::size_t i = begin; i < end; ++i) {
      if (outside_by(i) != furthest) continue;
      // The update's own terms (velocity and acceleration are still those it used).
      const auto v = p.velocity.get(i).template cast<double>();
      const auto a = p.acceleration.get(i).template cast<double>();
      const double t = double(dt), a_term = method_ == Method::VelocityVerlet ? 0.5 * t * t : 0.0;
      const auto moved = v * t + a * a_term;
      return {true, static_cast<std::uint64_t>(p.id[i]), double(furthest), norm(v), norm(a), norm(moved)};
    }
    return {};
  }

  // The position update of the method (eq. 4.2, or x += v·Δt after the first half kick).
  void move(ParticleSet<Real>& p, std::size_t begin, std::size_t end, Real dt) const {
    if (method_ == Method::VelocityVerlet) {
      drift(p, begin, end, dt);
      return;
    }
    for (int axis = 0; axis < 3; ++axis) {
      Real* x = p.position[axis].data();
      const Real* v = p.velocity[axis].data();
#pragma omp simd
      for (std::size_t i = begin; i < end; ++i) x[i] += v[i] * dt;
    }
  }

  static void half_kick(ParticleSet<Real>& p, std::size_t begin, std::size_t end, Real dt) {
    const Real half_dt = Real(0.5) * dt;
    for (int axis = 0; axis < 3; ++axis) {
      Real* v = p.velocity[axis].data();
      const Real* a = p.acceleration[axis].data();
#pragma omp simd
      for (std::size_t i = begin; i < end; ++i) v[i] += a[i] * half_dt;
    }
  }

  // Pass one, the velocity update and the scan of the new state.
  StepScan kick_block(ParticleSet<Real>& p, std::size_t begin, std::size_t end, Real dt, const StepRequest& r) const {
    if (box_) box_->reflect_velocities(p, begin, end);
    if (method_ == Method::VelocityVerlet)
      kick(p, begin, end, dt);
    else
      half_kick(p, begin, end, dt);
    if (r.scan) return scan_block(p, begin, end, r.needs);
    // Unchecked: only what the step loop always refused, a non-finite x or v.
    StepScan s;
    for (std::size_t i = begin; i < end; ++i) {
      const Real sum = p.position.x[i] + p.position.y[i] + p.position.z[i] + p.velocity.x[i] + p.velocity.y[i] +
                       p.velocity.z[i];
      if (!std::isfinite(sum)) {
        s.non_finite = i;
        break;
      }
    }
    return s;
  }

  Method method_;
  std::optional<boundary::BoxCollision<Real>> box_;
  std::vector<std::uint8_t> outside_before_;  // scratch of the box's pass two, one flag per particle
};

// Compiled once, in src/integrate/kick_drift.cpp: users link the float and double copies
// instead of compiling them again.
extern template class KickDriftStepper<float>;
extern template class KickDriftStepper<double>;

}  // namespace swirl::integrate
