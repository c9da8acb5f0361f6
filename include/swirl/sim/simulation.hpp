// Simulation<Real>: particles, force models, the box and the thesis's time step.
//
// The step (the thesis's Algorithm 1 and section 4.4). Algorithm 1 repeats the
// cycle
//     forces → box pass one → velocity update (4.1) → position update (4.2)
//     → a_prev = a → box pass two
// and swirl runs exactly this cycle, with the loop boundary placed after the
// velocity update instead of before the forces:
//
//   start():  a = F(x₀), a_prev = a                           (once)
//   step():   x ← x + v·Δt + ½·a·Δt², a_prev ← a               (4.2) ┐ "integrate"
//             box pass two for particles outside before and after    ┘
//             a ← F(x)   (every force model adds into a)             "forces"
//             box pass one: outward normal velocity ← −e·v_n        ┐ "integrate"
//             v ← v + ½·(a_prev + a)·Δt                       (4.1) ┘
//
// Placed there, x, v, a (and the density a force model computed) all belong to
// the same time between steps, so outputs and diagnostics are synchronous and
// the first step does not add a₀·Δt to v₀ (which the literal loop would do,
// breaking the exactness of velocity Verlet for constant acceleration).
//
// Determinism: every pass runs through parallel::for_blocks over fixed blocks
// and writes only its own block, so the state is bit-identical for any thread
// count. Time is step_count·Δt, never accumulated.
//
// A non-finite position or velocity after a step throws SimulationError; the
// state is then unusable, and whatever was written before stays valid.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "swirl/boundary/box_collision.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/force/force_model.hpp"
#include "swirl/integrate/velocity_verlet.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl {

// A run that cannot go on (non-finite state). what() names the step, time and particle id.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SimulationSettings {
  double dt = 0;                  // time step, s (> 0)
  std::size_t block_size = 1024;  // particles per work block (≥ 1)
  std::optional<boundary::BoxCollision<double>> box;  // walls; none = open space
};

template <class Real>
class Simulation {
 public:
  Simulation(ParticleSet<Real> particles, SimulationSettings settings)
      : particles_(std::move(particles)), settings_(std::move(settings)) {
    if (!(settings_.dt > 0) || !std::isfinite(settings_.dt)) throw std::invalid_argument("dt must be finite and > 0");
    if (settings_.block_size == 0) throw std::invalid_argument("block_size must be at least 1");
    if (settings_.box) box_ = boundary::BoxCollision<Real>{settings_.box->box.template cast<Real>(), Real(settings_.box->restitution)};
  }

  // Adds a force model; models add their accelerations in the order added.
  void add_force(std::unique_ptr<ForceModel<Real>> model) { forces_.push_back(std::move(model)); }

  // Computes a₀ = F(x₀) and sets a_prev = a₀. Call once before the first step().
  void start() {
    compute_forces();
    for (int axis = 0; axis < 3; ++axis) particles_.acceleration_prev[axis] = particles_.acceleration[axis];
    outside_before_.assign(particles_.size(), 0);
    started_ = true;
  }

  // Continues from a restored state instead of start(): the particles hold every
  // field as it was after step `step` (a checkpoint), so the next step() is the
  // one the original run would have taken.
  void resume(std::uint64_t step) {
    step_count_ = step;
    outside_before_.assign(particles_.size(), 0);
    started_ = true;
  }

  // Advances the state by one time step (see the header comment).
  void step() {
    if (!started_) throw std::logic_error("Simulation::step() before start()");
    const Real dt = Real(settings_.dt);
    {
      ScopedPhase phase(timers_, "integrate");
      parallel::for_blocks("drift", particles_.size(), settings_.block_size,
                           [&](std::size_t b, std::size_t e, std::size_t) { drift_block(b, e, dt); });
    }
    compute_forces_at(time_of(step_count_ + 1));
    {
      ScopedPhase phase(timers_, "integrate");
      constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
      const std::size_t bad = parallel::reduce_blocks(
          "kick", particles_.size(), settings_.block_size, none,
          [&](std::size_t b, std::size_t e) { return kick_block(b, e, dt); },
          [](std::size_t x, std::size_t y) { return x < y ? x : y; });
      ++step_count_;
      if (bad != none) throw_blow_up(bad);
    }
  }

  double time() const { return time_of(step_count_); }
  std::uint64_t step_count() const { return step_count_; }
  const SimulationSettings& settings() const { return settings_; }
  const ParticleSet<Real>& particles() const { return particles_; }
  ParticleSet<Real>& particles() { return particles_; }
  PhaseTimers& timers() { return timers_; }
  const PhaseTimers& timers() const { return timers_; }
  const std::vector<std::unique_ptr<ForceModel<Real>>>& forces() const { return forces_; }

 private:
  double time_of(std::uint64_t step) const { return static_cast<double>(step) * settings_.dt; }

  void compute_forces() { compute_forces_at(time()); }

  void compute_forces_at(double t) {
    ScopedPhase phase(timers_, "forces");
    parallel::for_blocks("zero_acceleration", particles_.size(), settings_.block_size,
                         [&](std::size_t b, std::size_t e, std::size_t) {
                           for (int axis = 0; axis < 3; ++axis) {
                             Real* a = particles_.acceleration[axis].data();
#pragma omp simd
                             for (std::size_t i = b; i < e; ++i) a[i] = Real(0);
                           }
                         });
    const ForceContext ctx{t, settings_.block_size, &timers_};
    for (auto& model : forces_) model->add_acceleration(particles_, ctx);
  }

  void drift_block(std::size_t begin, std::size_t end, Real dt) {
    if (!box_) {
      integrate::drift(particles_, begin, end, dt);
      return;
    }
    // Pass two needs to know who was outside before the position update.
    std::uint8_t* was_outside = outside_before_.data();
    for (std::size_t i = begin; i < end; ++i) was_outside[i] = box_->outside(particles_, i) ? 1 : 0;
    integrate::drift(particles_, begin, end, dt);
    for (std::size_t i = begin; i < end; ++i)
      if (was_outside[i]) box_->project_if_outside(particles_, i);
  }

  // Pass one and the velocity update; returns the first particle index in the
  // block with a non-finite position or velocity, or SIZE_MAX.
  std::size_t kick_block(std::size_t begin, std::size_t end, Real dt) {
    if (box_) box_->reflect_velocities(particles_, begin, end);
    integrate::kick(particles_, begin, end, dt);
    for (std::size_t i = begin; i < end; ++i) {
      const Real s = particles_.position.x[i] + particles_.position.y[i] + particles_.position.z[i] +
                     particles_.velocity.x[i] + particles_.velocity.y[i] + particles_.velocity.z[i];
      if (!std::isfinite(s)) return i;
    }
    return std::numeric_limits<std::size_t>::max();
  }

  [[noreturn]] void throw_blow_up(std::size_t i) const {
    throw SimulationError(fmt::format(
        "step {} (t = {:.6g}): particle id {} has a non-finite position or velocity "
        "(x = ({}, {}, {}), v = ({}, {}, {})); the time step is probably too large for the forces",
        step_count_, time(), particles_.id[i], particles_.position.x[i], particles_.position.y[i],
        particles_.position.z[i], particles_.velocity.x[i], particles_.velocity.y[i], particles_.velocity.z[i]));
  }

  ParticleSet<Real> particles_;
  SimulationSettings settings_;
  std::optional<boundary::BoxCollision<Real>> box_;
  std::vector<std::unique_ptr<ForceModel<Real>>> forces_;
  std::vector<std::uint8_t> outside_before_;  // scratch of the box's pass two, one flag per particle
  PhaseTimers timers_;
  std::uint64_t step_count_ = 0;
  bool started_ = false;
};

}  // namespace swirl
