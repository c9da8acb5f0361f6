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
// count. With a fixed Δt, time is step_count·Δt, never accumulated.
//
// Adaptive steps (SimulationSettings::adaptive): before each step Δt is chosen
// from the state the step starts from (sim/step_limits.hpp: the SPH CFL, force
// and viscous conditions, the gravity condition), capped by dt_max and by
// growth × the previous choice, and shortened to land exactly on a requested
// time (step(land_at)). The integrator stays the same velocity Verlet with that
// step: x_{n+1} = x_n + v_n·Δt_n + ½a_n·Δt_n², v_{n+1} = v_n + ½(a_n + a_{n+1})·Δt_n.
// Each step is still second-order accurate (local error O(Δt³)) and, since Δt_n
// is a smooth function of the state with bounded growth, so is the run; what is
// lost is exact time symmetry (Δt_n is decided at the start of the step, not
// symmetrically), so energy errors of long orbits can drift slowly instead of
// staying bounded. Schemes that restore it (e.g. iterating Δt to the midpoint)
// cost extra force evaluations per step; SPH is dissipative anyway, and gravity
// runs that need the bounded error keep a fixed Δt. The step size comes from a
// reduce_blocks fold, so it is bit-identical for any thread count; time is
// accumulated (t_{n+1} = t_n + Δt_n, or exactly the landing time).
//
// The guard (sim/blow_up.hpp): after each step the state is scanned in the
// velocity-update pass for non-finite fields and the extremes the time-step
// conditions need. A non-finite state throws SimulationError; a particle that
// left the box, a fixed Δt beyond a condition or a collapsed adaptive Δt throws
// too, or (OnBlowUp::Warn) is reported through take_events().
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
#include "swirl/sim/blow_up.hpp"
#include "swirl/sim/step_limits.hpp"

namespace swirl {

struct SimulationSettings {
  double dt = 0;                  // the time step, s (> 0); adaptive: the largest step (dt_max)
  std::size_t block_size = 1024;  // particles per work block (≥ 1)
  std::optional<boundary::BoxCollision<double>> box;  // walls; none = open space

  // Time-step conditions (sim/step_limits.hpp); none: nothing limits Δt.
  sim::StepLimitSettings limits;
  bool adaptive = false;          // choose Δt from the limits before every step
  double dt_min = 0;              // adaptive: a smaller Δt is a blow-up; 0: 1e-6 × the first step's
  double growth = 1.25;           // adaptive: Δt grows at most by this factor per step (> 1)
  // With a box: a particle further than this outside after a position update
  // has left the domain (scenes set the SPH kernel support h); 0: no check.
  double escape_length = 0;
  OnBlowUp on_blow_up = OnBlowUp::Stop;
};

template <class Real>
class Simulation {
 public:
  Simulation(ParticleSet<Real> particles, SimulationSettings settings)
      : particles_(std::move(particles)), settings_(std::move(settings)) {
    if (!(settings_.dt > 0) || !std::isfinite(settings_.dt)) throw std::invalid_argument("dt must be finite and > 0");
    if (settings_.block_size == 0) throw std::invalid_argument("block_size must be at least 1");
    if (settings_.adaptive && !(settings_.growth > 1)) throw std::invalid_argument("growth must be > 1");
    if (!(settings_.dt_min >= 0) || !(settings_.escape_length >= 0))
      throw std::invalid_argument("dt_min and escape_length must be >= 0");
    if (settings_.box) box_ = boundary::BoxCollision<Real>{settings_.box->box.template cast<Real>(), Real(settings_.box->restitution)};
  }

  // What a failed check does from now on (the settings' on_blow_up until then).
  void set_on_blow_up(OnBlowUp policy) { settings_.on_blow_up = policy; }

  // Adds a force model; models add their accelerations in the order added.
  void add_force(std::unique_ptr<ForceModel<Real>> model) { forces_.push_back(std::move(model)); }

  // Computes a₀ = F(x₀) and sets a_prev = a₀. Call once before the first step().
  void start() {
    compute_forces();
    for (int axis = 0; axis < 3; ++axis) particles_.acceleration_prev[axis] = particles_.acceleration[axis];
    outside_before_.assign(particles_.size(), 0);
    rescan();
    started_ = true;
  }

  // Continues from a restored state instead of start(): the particles hold every
  // field as it was after step `step` (a checkpoint), so the next step() is the
  // one the original run would have taken. Adaptive runs also restore the time
  // reached and the controller's state (adaptive_state()).
  void resume(std::uint64_t step, double time = 0, double previous_dt = 0, double dt_floor = 0) {
    step_count_ = step;
    time_ = time;
    previous_dt_ = previous_dt;
    dt_floor_ = dt_floor;
    outside_before_.assign(particles_.size(), 0);
    rescan();  // the limits are a function of the restored fields: the same as before the stop
    started_ = true;
  }

  // Advances the state by one time step (see the header comment). Adaptive
  // runs shorten the step so that it ends exactly at land_at if it would pass it.
  void step(std::optional<double> land_at = {}) {
    if (!started_) throw std::logic_error("Simulation::step() before start()");
    double dt_step = settings_.dt, t_next = time_of(step_count_ + 1);
    if (settings_.adaptive) {
      const double proposal = proposed_dt();
      if (dt_floor_ == 0) dt_floor_ = settings_.dt_min > 0 ? settings_.dt_min : 1e-6 * proposal;
      if (proposal < dt_floor_) throw_collapse(proposal);
      dt_step = proposal;
      t_next = time_ + dt_step;
      if (land_at && *land_at > time_) {
        const double remaining = *land_at - time_;
        // Within rounding of the choice, land (a step 1e-9 longer is no risk; two half steps would waste one).
        if (remaining <= dt_step * (1 + 1e-9)) {
          dt_step = remaining, t_next = *land_at;
        } else if (2 * dt_step > remaining) {
          dt_step = remaining / 2, t_next = time_ + dt_step;  // two equal steps, not one long and a sliver
        }
      }
      previous_dt_ = proposal;
    }
    const Real dt = Real(dt_step);
    const bool checks = settings_.on_blow_up != OnBlowUp::Off;
    const bool escapes = checks && box_ && settings_.escape_length > 0;
    Escape escape;
    {
      ScopedPhase phase(timers_, "integrate");
      escape = parallel::reduce_blocks_pinned(
          "drift", particles_.size(), settings_.block_size, Escape{},
          [&](std::size_t b, std::size_t e) { return drift_block(b, e, dt, escapes); },
          [](const Escape& x, const Escape& y) { return y.excess > x.excess ? y : x; });
    }
    compute_forces_at(t_next);
    {
      ScopedPhase phase(timers_, "integrate");
      scan_ = parallel::reduce_blocks_pinned(
          "kick", particles_.size(), settings_.block_size, sim::StepScan{},
          [&](std::size_t b, std::size_t e) { return kick_block(b, e, dt, checks); }, &sim::StepScan::combine);
      ++step_count_;
      time_ = t_next;
      last_dt_ = dt_step;
      limits_ = sim::evaluate_limits(scan_, settings_.limits, particles_.size());
    }
    if (scan_.non_finite != sim::kNoParticle) throw_non_finite(scan_.non_finite);
    if (!checks) return;
    if (escape.found) report(BlowUpCause::LeftDomain, escape_message(escape));
    const sim::StepLimit& tight = limits_.tightest();
    if (!settings_.adaptive && settings_.dt > tight.dt) report(BlowUpCause::TimeStep, condition_message(tight));
  }

  // The step the next step() takes before any landing: the fixed Δt, or the
  // adaptive choice min(tightest limit, dt_max, growth × previous choice).
  double proposed_dt() const {
    if (!settings_.adaptive) return settings_.dt;
    double dt = std::min(limits_.tightest().dt, settings_.dt);
    if (previous_dt_ > 0) dt = std::min(dt, settings_.growth * previous_dt_);
    return dt;
  }

  double time() const { return settings_.adaptive ? time_ : time_of(step_count_); }
  std::uint64_t step_count() const { return step_count_; }
  double last_dt() const { return last_dt_; }        // the step last taken (0 before the first)
  // The adaptive controller's state, for checkpoints: the previous unshortened
  // choice and the collapse floor (both 0 before the first step).
  double previous_dt() const { return previous_dt_; }
  double dt_floor() const { return dt_floor_; }
  // The time-step conditions of the current state.
  const sim::StepLimits& limits() const { return limits_; }
  const sim::StepScan& scan() const { return scan_; }
  // Failed checks of OnBlowUp::Warn since the last call.
  std::vector<GuardEvent> take_events() { return std::exchange(events_, {}); }
  const SimulationSettings& settings() const { return settings_; }
  const ParticleSet<Real>& particles() const { return particles_; }
  ParticleSet<Real>& particles() { return particles_; }
  PhaseTimers& timers() { return timers_; }
  const PhaseTimers& timers() const { return timers_; }
  const std::vector<std::unique_ptr<ForceModel<Real>>>& forces() const { return forces_; }

 private:
  // The particle that went furthest outside the box beyond escape_length. By
  // id, not index: the force pass that follows may reorder the particles.
  struct Escape {
    bool found = false;
    std::uint64_t id = 0;
    double excess = 0;  // distance outside the box, length units
    double speed = 0;   // |v| during the position update
  };

  double time_of(std::uint64_t step) const { return static_cast<double>(step) * settings_.dt; }

  void compute_forces() { compute_forces_at(time()); }

  void compute_forces_at(double t) {
    ScopedPhase phase(timers_, "forces");
    parallel::for_blocks_pinned("zero_acceleration", particles_.size(), settings_.block_size,
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

  bool wants_density() const { return settings_.limits.sph && settings_.limits.sph->viscosity > 0; }
  bool wants_bounds() const { return settings_.limits.gravity && !(settings_.limits.gravity->softening > 0); }

  // The scan of the current state outside a step (start, resume).
  void rescan() {
    scan_ = parallel::reduce_blocks_pinned(
        "scan", particles_.size(), settings_.block_size, sim::StepScan{},
        [&](std::size_t b, std::size_t e) { return sim::scan_block(particles_, b, e, wants_density(), wants_bounds()); },
        &sim::StepScan::combine);
    limits_ = sim::evaluate_limits(scan_, settings_.limits, particles_.size());
  }

  Escape drift_block(std::size_t begin, std::size_t end, Real dt, bool escapes) {
    Escape out;
    if (!box_) {
      integrate::drift(particles_, begin, end, dt);
      return out;
    }
    // Pass two needs to know who was outside before the position update.
    std::uint8_t* was_outside = outside_before_.data();
    for (std::size_t i = begin; i < end; ++i) was_outside[i] = box_->outside(particles_, i) ? 1 : 0;
    integrate::drift(particles_, begin, end, dt);
    for (std::size_t i = begin; i < end; ++i)
      if (was_outside[i]) box_->project_if_outside(particles_, i);
    if (!escapes) return out;
    // The block's largest distance outside (vectorised); particles only when it is too far.
    auto outside_by = [&](std::size_t i) {
      Real excess = 0;
      for (int axis = 0; axis < 3; ++axis) {
        const Real x = particles_.position[axis][i];
        excess = std::max(excess, std::max(box_->box.lo[axis] - x, x - box_->box.hi[axis]));
      }
      return excess;
    };
    Real furthest = 0;
#pragma omp simd reduction(max : furthest)
    for (std::size_t i = begin; i < end; ++i) furthest = std::max(furthest, outside_by(i));
    if (!(double(furthest) > settings_.escape_length)) return out;
    for (std::size_t i = begin; i < end; ++i) {
      if (outside_by(i) != furthest) continue;
      const auto v = particles_.velocity.get(i).template cast<double>();
      return {true, static_cast<std::uint64_t>(particles_.id[i]), double(furthest), std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z)};
    }
    return out;
  }

  // Pass one, the velocity update and the scan of the new state.
  sim::StepScan kick_block(std::size_t begin, std::size_t end, Real dt, bool checks) {
    if (box_) box_->reflect_velocities(particles_, begin, end);
    integrate::kick(particles_, begin, end, dt);
    if (checks || settings_.adaptive) return sim::scan_block(particles_, begin, end, wants_density(), wants_bounds());
    // Unchecked (OnBlowUp::Off): only what the step loop always refused, a non-finite x or v.
    sim::StepScan s;
    for (std::size_t i = begin; i < end; ++i) {
      const Real sum = particles_.position.x[i] + particles_.position.y[i] + particles_.position.z[i] +
                       particles_.velocity.x[i] + particles_.velocity.y[i] + particles_.velocity.z[i];
      if (!std::isfinite(sum)) {
        s.non_finite = i;
        break;
      }
    }
    return s;
  }

  // "step 12 (t = 0.0048)": where a message happened.
  std::string where() const { return fmt::format("step {} (t = {:.6g})", step_count_, time()); }

  std::string fix_for_dt(double suggested) const {
    std::string fix = settings_.adaptive ? std::string("fix: ")
                                         : fmt::format("fix: a smaller dt (at most {:.3g}), or dt = \"adaptive\"; ", suggested);
    if (settings_.limits.sph) fix += "if the fluid is exploding, a larger smoothing length h or sound speed c";
    else if (settings_.limits.gravity) fix += "for close encounters, a larger softening";
    else fix += "check the forces";
    return fix;
  }

  [[noreturn]] void throw_non_finite(std::size_t i) const {
    // Name every non-finite quantity of the particle, in field order.
    std::string names;
    for (const auto& f : particles_.fields())
      for (int c = 0; c < f.components; ++c)
        if (!std::isfinite(f.data[static_cast<std::size_t>(c)][i])) {
          names += fmt::format("{}{}", names.empty() ? "" : ", ", f.name);
          break;
        }
    const double suggested = settings_.adaptive ? last_dt_ : std::min(settings_.dt / 4, limits_.tightest().dt);
    throw SimulationError(
        fmt::format("{}: blow-up: particle id {} has a non-finite {} (x = ({}, {}, {}), v = ({}, {}, {})); "
                    "the time step {} is probably too large for the forces; {}",
                    where(), particles_.id[i], names, particles_.position.x[i], particles_.position.y[i],
                    particles_.position.z[i], particles_.velocity.x[i], particles_.velocity.y[i],
                    particles_.velocity.z[i], last_dt_, fix_for_dt(suggested)),
        BlowUpCause::NonFinite);
  }

  std::string escape_message(const Escape& e) const {
    return fmt::format(
        "{}: blow-up: particle id {} left the box: it ended a position update {:.3g} outside a wall, more than "
        "the kernel support h = {:.3g} (its speed was {:.3g}, so |v|·dt = {:.3g}); {}",
        where(), e.id, e.excess, settings_.escape_length, e.speed, e.speed * last_dt_,
        fix_for_dt(std::min(settings_.dt / 4, limits_.tightest().dt)));
  }

  std::string condition_message(const sim::StepLimit& l) const {
    const std::string id = l.particle < particles_.size() ? std::to_string(particles_.id[l.particle]) : "?";
    std::string rule, fix;
    if (l.condition == "cfl") {
      const auto& s = *settings_.limits.sph;
      rule = fmt::format("the CFL condition C_cfl·h/(c + |v|max) = {}·{:.3g}/({:.3g} + {:.3g}) = {:.6g} "
                         "(|v|max = {:.3g} at particle id {})",
                         s.cfl, s.smoothing_length, s.sound_speed, l.value, l.dt, l.value, id);
      fix = "or a larger smoothing length h";
    } else if (l.condition == "force") {
      const auto& s = *settings_.limits.sph;
      rule = fmt::format("the force condition C_force·sqrt(h/|a|max) = {}·sqrt({:.3g}/{:.3g}) = {:.6g} "
                         "(|a|max = {:.3g} at particle id {})",
                         s.force_factor, s.smoothing_length, l.value, l.dt, l.value, id);
      fix = "or a larger smoothing length h; if the fluid is exploding, a larger sound speed c";
    } else if (l.condition == "viscous") {
      const auto& s = *settings_.limits.sph;
      rule = fmt::format("the viscous condition C_visc·h²·ρ/μ = {}·{:.3g}²·{:.3g}/{:.3g} = {:.6g} "
                         "(ρ = {:.3g} at particle id {})",
                         s.viscous_factor, s.smoothing_length, l.value, s.viscosity, l.dt, l.value, id);
      fix = "or a smaller viscosity";
    } else {
      const auto& g = *settings_.limits.gravity;
      rule = fmt::format("the gravity condition η·sqrt({}/|a|max) with η = {} = {:.6g} (|a|max = {:.3g} at particle id {})",
                         g.softening > 0 ? "ε" : "d", g.eta, l.dt, l.value, id);
      fix = "or a larger softening ε";
    }
    return fmt::format("{}: blow-up: time step too large: dt = {:.6g} exceeds {}; fix: dt <= {:.6g}, or dt = \"adaptive\", {}",
                       where(), settings_.dt, rule, l.dt, fix);
  }

  [[noreturn]] void throw_collapse(double proposal) const {
    const sim::StepLimit& l = limits_.tightest();
    const std::string id = l.particle < particles_.size() ? std::to_string(particles_.id[l.particle]) : "?";
    throw SimulationError(
        fmt::format("{}: blow-up: the adaptive time step collapsed to {:.3g}, below dt_min = {:.3g}: the {} condition "
                    "is set by particle id {} ({} = {:.3g}); fix: {}",
                    where(), proposal, dt_floor_, l.condition, id,
                    l.condition == "cfl" ? "|v|" : (l.condition == "viscous" ? "ρ" : "|a|"), l.value,
                    settings_.limits.sph ? "a larger smoothing length h or sound speed c, a smaller viscosity, or check the scene's forces"
                                         : "a larger softening, or check the scene's forces"),
        BlowUpCause::StepCollapse);
  }

  void report(BlowUpCause cause, std::string message) {
    if (settings_.on_blow_up == OnBlowUp::Warn) {
      events_.push_back({cause, std::move(message)});
      return;
    }
    throw SimulationError(message, cause);
  }

  ParticleSet<Real> particles_;
  SimulationSettings settings_;
  std::optional<boundary::BoxCollision<Real>> box_;
  std::vector<std::unique_ptr<ForceModel<Real>>> forces_;
  std::vector<std::uint8_t> outside_before_;  // scratch of the box's pass two, one flag per particle
  PhaseTimers timers_;
  std::uint64_t step_count_ = 0;
  double time_ = 0;         // adaptive: the time reached (fixed Δt: step_count_·Δt instead)
  double last_dt_ = 0;      // the step last taken
  double previous_dt_ = 0;  // adaptive: the previous unshortened choice
  double dt_floor_ = 0;     // adaptive: the collapse floor, fixed at the first step
  sim::StepScan scan_;
  sim::StepLimits limits_;
  std::vector<GuardEvent> events_;
  bool started_ = false;
};

}  // namespace swirl
