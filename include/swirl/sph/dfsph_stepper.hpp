// DfsphStepper<Real>: divergence-free SPH's time step (Bender & Koschier,
// SCA 2015, Algorithm 1; TVCG 2017, Algorithms 1–3) behind the Stepper seam
// (integrate/stepper.hpp). It lives in the SPH module, not in integrate/,
// because it drives the fluid's own passes (sph/dfsph_passes.hpp through
// SphFluid): a stepper in integrate/ may know forces only.
//
// Between steps, as every stepper keeps it: x, v belong to one time; ρ and
// α (the fluid's evaluation at x) and a = a_np, the non-pressure acceleration
// (every solver's, gravity included, plus the fluid's viscosity from the final
// v, surface tension and adhesion). One step of Δt:
//   1. v* = v + Δt·a_np
//   2. constant-density solve (2017, Algorithm 3), on the grid at x:
//        warm start: κ_i ← ½ κ_i, the κ the last step ended with (field
//        "dfsph_kappa"), halved; v* −= Δt Σ_j m_j (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij;
//        repeat: ρ*_i = ρ_i + Δt (Dρ/Dt)_i(v*),
//                error = mean_i max(ρ*_i − ρ0, 0) / ρ0,
//                stop when error ≤ η after at least 2 iterations, or at the cap;
//                Δκ_i = (ρ*_i − ρ0)/Δt² · α_i, v* −= Δt Σ_j m_j (Δκ_i/ρ_i + Δκ_j/ρ_j) ∇W_ij,
//                κ_i += Δκ_i
//   3. x += Δt·v*; the box (if any) projects a particle that crossed a wall
//      back onto it and reflects its outward normal velocity (−e·v_n); the
//      walls also act as a velocity constraint inside the solves (hold_at_walls:
//      no velocity carries a particle through a wall), so this projection
//      only catches rounding
//   4. the forces' evaluation at the new x: the sort, ρ, α, a_np (solvers)
//   5. divergence-free solve (2017, Algorithm 2), the same with
//        error = mean_i max((Dρ/Dt)_i, 0)·Δt/ρ0 ≤ η_v (at least 1 iteration),
//        Δκ^v_i = (Dρ/Dt)_i/Δt · α_i, warm-started from "dfsph_kappa_v"
//   6. XSPH (sph.xsph = ε > 0): v ← v + Δv of the filter, once, on the final
//      v (the grid and ρ of step 4; sph/dfsph_passes.hpp, dfsph_xsph_change);
//      it is the step's last change of v, so frames see the filtered velocity
//   7. a_np += the fluid's viscosity from the final v, and surface tension and
//      adhesion (Akinci et al. 2013) at the new x; the scan.
// Each iteration's Δκ is clamped at 0 (only compression is corrected: the
// papers' ρ* ← max(ρ*, ρ0), no tension at the free surface), and the errors
// count compression only, so an under-dense surface particle is no error. A
// projected variant that lets Δκ go down to −κ (so that an iteration could
// take back a warm start's overshoot) was tried and diverged on the dam break
// (the error grew from 0.17 % to 2 % over 30 iterations): the Jacobi step
// with α's approximate diagonal overshoots the high-frequency modes, and only
// the one-sided clamp damps them.
// Ours, beyond the papers:
//  - The warm start takes half of the last κ, not all of it: with increments
//    clamped at 0 a full warm start is a ratchet (κ can only grow, and a
//    particle once compressed is pushed ever harder: a dam-break surface
//    particle reached 24 m/s in 14 steps); halved, a κ no longer needed decays
//    by half per step while the iterations add what is still missing.
//  - κ is stored as such (m²/s², p/ρ: independent of Δt), so warm starts stay
//    right when an adaptive Δt changes.
//  - The non-pressure acceleration of the next step is computed at the end of
//    this one (from the final v), so it is part of the state between steps.
// A solve that reaches sph.dfsph.max_iterations above its tolerance is reported
// to the guard (BlowUpCause::NotConverged: "solver did not converge").
//
// Boundary particles (core/particle_kind.hpp, sph/sph_fluid.hpp) are in every
// pass as neighbours and skipped as particles: κ_b stays 0, v_b stays 0, and
// a = 0 (the simulation zeroes it), so the kick and the drift leave them put.
// A moving obstacle's particles (boundary/moving_boundaries.hpp) carry their
// prescribed v_b through the step's solves (the walls' hold leaves boundary
// particles alone), and the evaluation of step 4 puts them at their exact x
// and v for the new time, whatever the drift did to them.
//
// Resume: the warm starts are particle fields; the grid and α are not, so the
// first step after a resume re-evaluates the forces at the restored x (the
// same bits: the same positions in the same order) before step 1, leaving the
// fluid's evaluation tally (its state: the summary's mean neighbour count) as
// the uninterrupted run has it, so the checkpoints that follow are its bytes.
//
// Determinism: every pass gathers into particle i over the grid's fixed order;
// the errors that stop the solves are block-ordered sums (parallel::
// reduce_blocks), so the iteration counts and every bit are the same for any
// thread count. On several ranks (SphFluid's passes run among ghosts, see
// sph_fluid.hpp) the same sums are formed across the ranks in the one-rank
// blocks of the global order (dist/block_sum.hpp: the raw values of a block
// cut by a rank boundary travel), so every rank count gives the one-rank bits
// too; the CFL limit is the simulation's global scan.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "swirl/boundary/box_collision.hpp"
#include "swirl/core/named_values.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/force/step_scan.hpp"
#include "swirl/integrate/stepper.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace swirl::sph {

// One solve's outcome.
struct DfsphSolve {
  std::uint32_t iterations = 0;
  double error = 0;  // the last measured average error (relative)
  bool converged = true;
};

template <class Real>
class DfsphStepper final : public integrate::Stepper<Real> {
 public:
  // `fluid` is the simulation's SPH solver (owned by it; it outlives the stepper's use).
  DfsphStepper(SphFluid<Real>& fluid, std::optional<boundary::BoxCollision<Real>> box = std::nullopt)
      : fluid_(fluid), box_(std::move(box)) {
    if (!fluid.dfsph()) throw std::invalid_argument("DfsphStepper: the SPH solver's method is not \"dfsph\"");
  }

  std::string_view name() const override { return "dfsph"; }

  void start(ParticleSet<Real>& p, integrate::Forces& forces, double time, std::size_t block_size) override {
    forces.evaluate(time);
    fluid_.add_non_pressure(p, block_size);
  }

  integrate::StepOutcome advance(ParticleSet<Real>& p, integrate::Forces& forces,
                                 const integrate::StepRequest& r) override {
    const Real dt = Real(r.dt);
    const std::size_t bs = r.block_size;
    if (refresh_) {  // after a resume: the grid and α at the restored positions
      // (the evaluation the uninterrupted run made at the end of the last step:
      // not counted twice in the fluid's tally, which the checkpoint holds)
      const auto tally = fluid_.tally();
      forces.evaluate(r.t_next - r.dt);
      fluid_.set_tally(tally);
      fluid_.add_non_pressure(p, bs);
      refresh_ = false;
    }
    integrate::StepOutcome out;
    {
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "integrate");
      parallel::for_blocks_pinned("dfsph_kick", p.size(), bs, [&](std::size_t b, std::size_t e, std::size_t) {
        for (int axis = 0; axis < 3; ++axis) {
          Real* v = p.velocity[axis].data();
          const Real* a = p.acceleration[axis].data();
#pragma omp simd
          for (std::size_t i = b; i < e; ++i) v[i] += a[i] * dt;
        }
        hold_at_walls(p, b, e, dt);
      });
    }
    {
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "dfsph.density");
      last_density_ = solve(p, dt, bs, Solve::Density);
      // The walls' share of that solve's impulse, while x, ρ and the grid are the ones it used.
      if (fluid_.records_boundary_reactions()) fluid_.record_density_reaction(p, bs);
    }
    {
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "integrate");
      out.escape = parallel::reduce_blocks_pinned(
          "dfsph_drift", p.size(), bs, integrate::Escape{},
          [&](std::size_t b, std::size_t e) { return drift_block(p, b, e, dt, r.escape_length); },
          [](const integrate::Escape& x, const integrate::Escape& y) { return y.excess > x.excess ? y : x; });
    }
    forces.evaluate(r.t_next);
    {
      std::optional<ScopedPhase> phase;
      if (r.timers) phase.emplace(*r.timers, "dfsph.divergence");
      last_divergence_ = solve(p, dt, bs, Solve::Divergence);
    }
    fluid_.apply_xsph(p, bs);
    fluid_.add_non_pressure(p, bs);
    record();
    for (const auto& [s, what, tolerance, unit] :
         {std::tuple{&last_density_, "constant-density", fluid_.parameters().dfsph.density_tolerance, "average compression"},
          std::tuple{&last_divergence_, "divergence-free", fluid_.parameters().dfsph.divergence_tolerance,
                     "average density change per step"}})
      if (!s->converged && out.not_converged.empty())
        out.not_converged = fmt::format(
            "DFSPH's {} solver did not converge: {} {:.4g} % after {} iterations, above the tolerance {:.4g} % "
            "(dt = {:.4g}); fix: a smaller dt (or a smaller sph.dfsph.cfl with dt = \"adaptive\"), or a larger "
            "sph.dfsph.max_iterations",
            what, unit, 100 * s->error, s->iterations, 100 * tolerance, r.dt);
    std::optional<ScopedPhase> phase;
    if (r.timers) phase.emplace(*r.timers, "integrate");
    out.scan = parallel::reduce_blocks_pinned(
        "dfsph_scan", p.size(), bs, StepScan{},
        [&](std::size_t b, std::size_t e) { return scan_block(p, b, e, r.needs); }, &StepScan::combine);
    return out;
  }

  const DfsphSolve& last_density_solve() const { return last_density_; }
  const DfsphSolve& last_divergence_solve() const { return last_divergence_; }

  std::vector<std::string> diagnostic_columns() const override {
    return {"dfsph_density_iterations", "dfsph_density_error", "dfsph_divergence_iterations", "dfsph_divergence_error"};
  }
  // The last step's solves (0 before the first step).
  void add_diagnostics(std::vector<double>& row) const override {
    row.insert(row.end(), {double(last_density_.iterations), last_density_.error, double(last_divergence_.iterations),
                           last_divergence_.error});
  }
  void add_metrics(NamedValues& out) const override {
    const double steps = std::max(steps_, 1.0);
    out.emplace_back("dfsph_mean_density_iterations", density_iterations_ / steps);
    out.emplace_back("dfsph_mean_divergence_iterations", divergence_iterations_ / steps);
    out.emplace_back("dfsph_max_density_iterations", max_density_iterations_);
    out.emplace_back("dfsph_max_divergence_iterations", max_divergence_iterations_);
    out.emplace_back("dfsph_max_density_error", max_density_error_);
    out.emplace_back("dfsph_max_divergence_error", max_divergence_error_);
  }
  void save_state(NamedValues& out) const override {
    out.insert(out.end(), {{"dfsph.steps", steps_},
                           {"dfsph.density_iterations", density_iterations_},
                           {"dfsph.divergence_iterations", divergence_iterations_},
                           {"dfsph.max_density_iterations", max_density_iterations_},
                           {"dfsph.max_divergence_iterations", max_divergence_iterations_},
                           {"dfsph.max_density_error", max_density_error_},
                           {"dfsph.max_divergence_error", max_divergence_error_},
                           {"dfsph.last_density_iterations", double(last_density_.iterations)},
                           {"dfsph.last_density_error", last_density_.error},
                           {"dfsph.last_divergence_iterations", double(last_divergence_.iterations)},
                           {"dfsph.last_divergence_error", last_divergence_.error}});
  }
  void load_state(const NamedValues& values) override {
    auto get = [&](std::string_view k) { return find_value(values, k).value_or(0.0); };
    steps_ = get("dfsph.steps");
    density_iterations_ = get("dfsph.density_iterations");
    divergence_iterations_ = get("dfsph.divergence_iterations");
    max_density_iterations_ = get("dfsph.max_density_iterations");
    max_divergence_iterations_ = get("dfsph.max_divergence_iterations");
    max_density_error_ = get("dfsph.max_density_error");
    max_divergence_error_ = get("dfsph.max_divergence_error");
    last_density_ = {static_cast<std::uint32_t>(get("dfsph.last_density_iterations")), get("dfsph.last_density_error"), true};
    last_divergence_ = {static_cast<std::uint32_t>(get("dfsph.last_divergence_iterations")),
                        get("dfsph.last_divergence_error"), true};
    refresh_ = true;
  }

 private:
  enum class Solve { Density, Divergence };
  // The share of the last step's κ a solve starts from (see the header).
  static constexpr Real kWarmShare = Real(0.5);

  // One solve (see the header): warm start, then Jacobi iterations until the
  // average error is within the tolerance or the cap is reached.
  DfsphSolve solve(ParticleSet<Real>& p, Real dt, std::size_t bs, Solve kind) {
    const auto& opt = fluid_.parameters().dfsph;
    const bool density = kind == Solve::Density;
    const double tolerance = density ? opt.density_tolerance : opt.divergence_tolerance;
    const std::uint32_t cap = opt.max_iterations;
    const std::uint32_t min_iterations = std::min<std::uint32_t>(density ? 2 : 1, cap);
    const std::size_t n = p.size();
    const std::size_t field = p.find_field(density ? SphFluid<Real>::kKappaField : SphFluid<Real>::kKappaVField);
    if (field == ParticleSet<Real>::npos) throw std::logic_error("DfsphStepper: the fluid's warm-start fields are not declared");
    Real* kappa = p.extra(field).data();
    const Real* rho = p.density.data();
    const Real* alpha = fluid_.factor();
    const Real rho0 = Real(fluid_.parameters().rest_density);
    change_.resize(n);
    k_over_rho_.resize(n);
    Real* d = change_.data();
    Real* kr = k_over_rho_.data();
    // Warm start with a share of the last step's κ (see the header).
    parallel::for_blocks_pinned("dfsph_warm", n, bs, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        kappa[i] *= kWarmShare;
        kr[i] = kappa[i] / rho[i];
      }
    });
    pressure_velocity(p, kr, dt, bs);
    DfsphSolve s;
    // The average over the fluid: boundary particles (static, ρ = ρ0, Dρ/Dt = 0) add no error.
    const std::size_t fluid = fluid_.fluid_count(p);
    const double scale = fluid ? 1.0 / (double(fluid) * double(rho0)) : 0.0;
    for (;;) {
      fluid_.density_change(p, d, bs);
      // Σ_i of the compression (ρ* − ρ0, or Dρ/Dt·Δt), positive parts only, in block order.
      const auto compression = [&](std::size_t i) {
        const Real excess = density ? rho[i] + dt * d[i] - rho0 : dt * d[i];
        return excess > Real(0) ? double(excess) : 0.0;
      };
      double sum = 0;
      if (fluid_.on_ranks()) {  // the one-rank block order across the ranks (the same bits)
        errors_.resize(n);
        parallel::for_blocks_pinned("dfsph_error", n, bs, [&](std::size_t b, std::size_t e, std::size_t) {
          for (std::size_t i = b; i < e; ++i) errors_[i] = compression(i);
        });
        sum = fluid_.block_sum(errors_, bs);
      } else {
        sum = parallel::reduce_blocks_pinned(
            "dfsph_error", n, bs, 0.0,
            [&](std::size_t b, std::size_t e) {
              double t = 0;
              for (std::size_t i = b; i < e; ++i) t += compression(i);
              return t;
            },
            [](double a, double b) { return a + b; });
      }
      s.error = sum * scale;
      if ((s.iterations >= min_iterations && s.error <= tolerance) || s.iterations >= cap) break;
      const Real inv_dt2 = Real(1) / (dt * dt), inv_dt = Real(1) / dt;
      parallel::for_blocks_pinned("dfsph_kappa", n, bs, [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t i = b; i < e; ++i) {
          const Real residual = density ? (rho[i] + dt * d[i] - rho0) * inv_dt2 : d[i] * inv_dt;
          const Real delta = std::max(residual * alpha[i], Real(0));  // compression only (see the header)
          kappa[i] += delta;
          kr[i] = delta / rho[i];
        }
      });
      pressure_velocity(p, kr, dt, bs);
      ++s.iterations;
    }
    s.converged = s.error <= tolerance;
    if (density) {  // the pressure of the solve, p = κ·ρ, for the frames
      Real* pressure = p.pressure.data();
      parallel::for_blocks_pinned("dfsph_pressure_out", n, bs, [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t i = b; i < e; ++i) pressure[i] = kappa[i] * rho[i];
      });
    }
    return s;
  }

  // The pressure pass, then the walls' hold on the new velocities.
  void pressure_velocity(ParticleSet<Real>& p, const Real* kr, Real dt, std::size_t bs) {
    fluid_.pressure_velocity(p, kr, dt, bs);
    if (box_)
      parallel::for_blocks_pinned("dfsph_walls", p.size(), bs,
                                  [&](std::size_t b, std::size_t e, std::size_t) { hold_at_walls(p, b, e, dt); });
  }

  // The box as a velocity constraint: a velocity that would carry a particle
  // through a wall within Δt is cut to the one that lands it on the wall,
  //   v_n ← max(v_n, (lo − x)/Δt)  (and the mirror at hi),
  // so the solves predict densities with motions the walls allow (without it,
  // a pressure that pushes a floor particle into the floor is undone by the
  // projection after the drift, and the step's prediction is wrong by that
  // much: the dam break's floor layer reached 6 m/s in 12 steps).
  void hold_at_walls(ParticleSet<Real>& p, std::size_t b, std::size_t e, Real dt) const {
    if (!box_) return;
    const std::int32_t* kind = SphFluid<Real>::kinds(p);  // boundary particles keep their (prescribed) velocity
    const Real inv_dt = Real(1) / dt;
    for (int axis = 0; axis < 3; ++axis) {
      const Real* x = p.position[axis].data();
      Real* v = p.velocity[axis].data();
      const Real lo = box_->box.lo[axis], hi = box_->box.hi[axis];
#pragma omp simd
      for (std::size_t i = b; i < e; ++i) {
        const Real low = (lo - x[i]) * inv_dt, high = (hi - x[i]) * inv_dt;
        const Real held = std::min(std::max(v[i], low), high);
        v[i] = kind && is_boundary(kind[i]) ? v[i] : held;
      }
    }
  }

  // x += Δt·v, then the box: a particle outside is projected back onto it with
  // its outward normal velocity reflected (−e·v_n). Returns the particle
  // furthest outside before the projection when beyond escape_length.
  integrate::Escape drift_block(ParticleSet<Real>& p, std::size_t b, std::size_t e, Real dt, double escape_length) const {
    for (int axis = 0; axis < 3; ++axis) {
      Real* x = p.position[axis].data();
      const Real* v = p.velocity[axis].data();
#pragma omp simd
      for (std::size_t i = b; i < e; ++i) x[i] += v[i] * dt;
    }
    if (!box_) return {};
    integrate::Escape worst;
    for (std::size_t i = b; i < e; ++i) {
      if (!box_->outside(p, i)) continue;
      if (escape_length > 0) {
        Real excess = 0;
        for (int axis = 0; axis < 3; ++axis) {
          const Real x = p.position[axis][i];
          excess = std::max(excess, std::max(box_->box.lo[axis] - x, x - box_->box.hi[axis]));
        }
        if (double(excess) > escape_length && double(excess) > worst.excess) {
          const auto v = p.velocity.get(i).template cast<double>();
          const auto a = p.acceleration.get(i).template cast<double>();
          worst = {true, static_cast<std::uint64_t>(p.id[i]), double(excess), norm(v), norm(a), norm(v) * double(dt)};
        }
      }
      box_->reflect_velocities(p, i, i + 1);
      box_->project_if_outside(p, i);
    }
    return worst;
  }

  void record() {
    steps_ += 1;
    density_iterations_ += last_density_.iterations;
    divergence_iterations_ += last_divergence_.iterations;
    max_density_iterations_ = std::max(max_density_iterations_, double(last_density_.iterations));
    max_divergence_iterations_ = std::max(max_divergence_iterations_, double(last_divergence_.iterations));
    max_density_error_ = std::max(max_density_error_, last_density_.error);
    max_divergence_error_ = std::max(max_divergence_error_, last_divergence_.error);
  }

  SphFluid<Real>& fluid_;
  std::optional<boundary::BoxCollision<Real>> box_;
  AlignedVector<Real> change_, k_over_rho_;  // scratch: (Dρ/Dt)_i and Δκ_i/ρ_i
  std::vector<double> errors_;               // scratch on ranks: each particle's compression
  DfsphSolve last_density_, last_divergence_;
  double steps_ = 0, density_iterations_ = 0, divergence_iterations_ = 0;
  double max_density_iterations_ = 0, max_divergence_iterations_ = 0, max_density_error_ = 0, max_divergence_error_ = 0;
  bool refresh_ = false;
};

// Compiled once, in src/sph/dfsph_stepper.cpp: users link the float and double copies
// instead of compiling them again.
extern template class DfsphStepper<float>;
extern template class DfsphStepper<double>;

}  // namespace swirl::sph
