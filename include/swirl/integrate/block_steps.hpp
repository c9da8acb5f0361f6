// BlockStepper<Real>: individual time steps in power-of-two bins, the
// hierarchical kick–drift–kick leapfrog of production N-body codes.
//
// Bins: particle i is in bin k_i ∈ [0, max_bin], with its own step
// Δt_i = Δt / 2^k_i, Δt the simulation's step (the largest). Its condition
// is the gravity condition of gravity_force.hpp taken per particle,
//   Δt_i ≤ η · sqrt(ε / |a_i|)        (ε the softening, η as the global one),
// k_i the smallest bin that meets it (bin 0 when a = 0).
//
// One simulation step of Δt is a cycle of sub-steps on an integer grid of
// ticks τ = Δt / 2^max_bin, so steps nest exactly and never drift apart:
//   tick 0: every particle opens its step:        v += ½·a·Δt_i
//   until tick 2^max_bin:
//     next tick: n += 2^(max_bin − k_finest), k_finest the finest bin in use
//     drift every particle:                       x += v·(ticks·τ)
//     active = the particles whose steps end at n: bin ≥ max_bin − tz(n)
//              (tz: trailing zero bits; a finer bin's steps end at every
//              coarser one's ends), so the active set is one number
//     a ← F(x) for the active ones only           (Forces::evaluate_active)
//     close their steps:                          v += ½·a·Δt_i
//     new bin from the new a, no coarser than the tick allows (a step starts
//       on a multiple of its own length: k ≥ max_bin − tz(n));
//     unless n is the end, open the next step:    v += ½·a·Δt_i(new)
// At the end every particle is synchronised: x, v, a (and the potential)
// belong to one time, so outputs, diagnostics, the guard and checkpoints see
// an ordinary state, and output times that are multiples of Δt are landed on
// exactly. The bins are a function of that state (each particle's last
// sub-step chose freely), so a checkpoint needs nothing more and a resumed run
// is bit-identical; they are kept in the integer field "time_bin", written
// to frames so ParaView shows them. With every particle in bin 0 (or max_bin = 0) one cycle
// is the leapfrog of kick_drift.hpp, bit for bit.
//
// Cost: forces only for the active particles (solvers told so by the active
// set; the linear tree walks only their groups); the drift, the particle
// order and the tree are refreshed for all particles at every sub-step.
//
// Determinism: every pass runs over fixed blocks and writes only its own
// block; the finest bin is a max-reduction (over the ranks too: each rank
// steps its own particles, StepRequest::ranks): bit-identical for any thread
// and rank count.
// No walls: a box's reflections belong to a whole step (the scene refuses
// block steps with walls).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "swirl/core/named_values.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/force/step_scan.hpp"
#include "swirl/integrate/stepper.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::integrate {

struct BlockStepOptions {
  double eta = 0.75;     // η of the condition
  double softening = 0;  // ε of the condition (> 0)
  int max_bin = 20;      // the finest bin: Δt / 2^max_bin, in [0, 40]
};

template <class Real>
class BlockStepper final : public Stepper<Real> {
 public:
  static constexpr int kMaxBins = 40;

  explicit BlockStepper(const BlockStepOptions& options) : options_(options) {
    if (!(options.eta > 0) || !std::isfinite(options.eta))
      throw std::invalid_argument("block time steps: eta must be finite and > 0");
    if (!(options.softening > 0) || !std::isfinite(options.softening))
      throw std::invalid_argument(
          "block time steps: the bin condition eta*sqrt(eps/|a|) needs a softening eps > 0 (nbody.softening)");
    if (options.max_bin < 0 || options.max_bin > kMaxBins)
      throw std::invalid_argument("block time steps: max_bin must be in [0, 40]");
  }

  std::string_view name() const override { return "block_leapfrog"; }
  const BlockStepOptions& options() const { return options_; }

  void declare_fields(ParticleSet<Real>& p) override { p.add_int_field(std::string(kTimeBinField)); }

  void start(ParticleSet<Real>& /*p*/, Forces& forces, double time, std::size_t /*block_size*/) override {
    forces.evaluate(time);
  }

  StepOutcome advance(ParticleSet<Real>& p, Forces& forces, const StepRequest& r) override {
    const std::uint64_t total = std::uint64_t(1) << options_.max_bin;  // ticks per step
    const double tick = r.dt / double(total);
    const double t0 = r.t_next - r.dt;
    dt_ = r.dt;
    std::int32_t* bin = bins(p);
    {
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "integrate");
      // Every particle's bin from its a (after a step, the bins its last
      // sub-step chose freely, so the same: a resumed run needs nothing else),
      // and the opening half kicks.
      finest_ = parallel::reduce_blocks_pinned(
          "block_open", p.size(), r.block_size, std::int32_t(0),
          [&](std::size_t b, std::size_t e) {
            std::int32_t finest = 0;
            for (std::size_t i = b; i < e; ++i) {
              bin[i] = desired_bin(p, i);
              kick(p, i, half_step(bin[i]));
              finest = std::max(finest, bin[i]);
            }
            return finest;
          },
          [](std::int32_t x, std::int32_t y) { return std::max(x, y); });
      finest_ = over_ranks(r, {finest_, 0}).finest;
    }
    std::uint64_t n = 0;
    while (n < total) {
      const std::uint64_t ticks = total >> finest_;
      {
        std::optional<ScopedPhase> phase;
        if (r.timers) phase.emplace(*r.timers, "integrate");
        const Real dx = Real(double(ticks) * tick);
        parallel::for_blocks_pinned("block_drift", p.size(), r.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
          for (int axis = 0; axis < 3; ++axis) {
            Real* x = p.position[axis].data();
            const Real* v = p.velocity[axis].data();
#pragma omp simd
            for (std::size_t i = b; i < e; ++i) x[i] += v[i] * dx;
          }
        });
      }
      n += ticks;
      const bool last = n == total;
      // Steps of bins >= min_bin end at n.
      const std::int32_t min_bin = last ? 0 : std::int32_t(options_.max_bin - std::countr_zero(n));
      if (last)
        forces.evaluate(r.t_next);
      else
        forces.evaluate_active(t0 + double(n) * tick, min_bin);
      ++sub_steps_;
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "integrate");
      bin = bins(p);  // the evaluation may have reordered the particles
      const Fold fold = parallel::reduce_blocks_pinned(
          "block_kick", p.size(), r.block_size, Fold{},
          [&](std::size_t b, std::size_t e) {
            Fold f;
            for (std::size_t i = b; i < e; ++i) {
              if (bin[i] >= min_bin) {
                kick(p, i, half_step(bin[i]));
                bin[i] = std::max(desired_bin(p, i), min_bin);
                if (!last) kick(p, i, half_step(bin[i]));
                ++f.active;
              }
              f.finest = std::max(f.finest, bin[i]);
            }
            return f;
          },
          [](Fold x, const Fold& y) { return Fold{std::max(x.finest, y.finest), x.active + y.active}; });
      const Fold all = over_ranks(r, fold);
      finest_ = all.finest;
      active_updates_ += double(all.active);
    }
    ++steps_;
    StepOutcome out;
    std::optional<ScopedPhase> phase;
    if (r.timers) phase.emplace(*r.timers, "integrate");
    out.scan = parallel::reduce_blocks_pinned(
        "block_scan", p.size(), r.block_size, StepScan{},
        [&](std::size_t b, std::size_t e) { return scan_block(p, b, e, r.needs); }, &StepScan::combine);
    out.finest_dt = std::ldexp(r.dt, -finest_);
    out.finest_fix = "or a larger simulation.max_bin (finest bin now " + std::to_string(finest_) + ")";
    return out;
  }

  // Sub-steps taken and particle updates (active particles summed over sub-steps), over the run.
  double sub_steps() const { return sub_steps_; }
  double active_updates() const { return active_updates_; }

  void add_metrics(NamedValues& out) const override {
    out.emplace_back("block_sub_steps", sub_steps_);
    out.emplace_back("block_sub_steps_per_step", steps_ > 0 ? sub_steps_ / steps_ : 0.0);
    out.emplace_back("block_finest_bin", double(finest_));
  }
  void save_state(NamedValues& out) const override {
    out.emplace_back("block_leapfrog.sub_steps", sub_steps_);
    out.emplace_back("block_leapfrog.active_updates", active_updates_);
    out.emplace_back("block_leapfrog.steps", steps_);
  }
  void load_state(const NamedValues& values) override {
    sub_steps_ = find_value(values, "block_leapfrog.sub_steps").value_or(0.0);
    active_updates_ = find_value(values, "block_leapfrog.active_updates").value_or(0.0);
    steps_ = find_value(values, "block_leapfrog.steps").value_or(0.0);
  }

 private:
  static std::int32_t* bins(ParticleSet<Real>& p) {
    const std::size_t k = p.find_int_field(kTimeBinField);
    if (k == ParticleSet<Real>::npos) throw std::logic_error("BlockStepper: time bins not declared");
    return p.int_field(k).data();
  }

  // A pass's finest bin and its count of active particles.
  struct Fold {
    std::int32_t finest = 0;
    std::uint64_t active = 0;
  };
  // On several ranks every rank takes the sub-steps of the finest bin of all
  // and counts every rank's active particles: one all-gather of each rank's
  // pair packed as active·64 + finest (a bin is at most 40).
  static Fold over_ranks(const StepRequest& r, const Fold& mine) {
    if (!r.ranks) return mine;
    Fold all;
    for (const std::uint64_t packed : r.ranks->all_gather(mine.active * 64 + std::uint64_t(mine.finest))) {
      all.finest = std::max(all.finest, std::int32_t(packed % 64));
      all.active += packed / 64;
    }
    return all;
  }

  // ½·Δt / 2^k, exact in double and rounded once.
  Real half_step(std::int32_t k) const { return Real(std::ldexp(0.5 * dt_, -k)); }

  static void kick(ParticleSet<Real>& p, std::size_t i, Real half) {
    p.velocity.x[i] += p.acceleration.x[i] * half;
    p.velocity.y[i] += p.acceleration.y[i] * half;
    p.velocity.z[i] += p.acceleration.z[i] * half;
  }

  // The smallest bin k with Δt / 2^k ≤ η·sqrt(ε/|a|), at most max_bin (the
  // guard reports a particle that needs more through finest_dt).
  std::int32_t desired_bin(const ParticleSet<Real>& p, std::size_t i) const {
    const double ax = double(p.acceleration.x[i]), ay = double(p.acceleration.y[i]), az = double(p.acceleration.z[i]);
    const double a = std::sqrt(ax * ax + ay * ay + az * az);
    if (!(a > 0)) return 0;
    const double limit = options_.eta * std::sqrt(options_.softening / a);
    std::int32_t k = 0;
    while (k < options_.max_bin && std::ldexp(dt_, -k) > limit) ++k;
    return k;
  }

  BlockStepOptions options_;
  double dt_ = 0;  // the step being taken
  std::int32_t finest_ = 0;
  double sub_steps_ = 0, active_updates_ = 0, steps_ = 0;
};

// Compiled once, in src/integrate/block_steps.cpp: users link the float and double copies
// instead of compiling them again.
extern template class BlockStepper<float>;
extern template class BlockStepper<double>;

}  // namespace swirl::integrate
