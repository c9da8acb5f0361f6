// SphFluid<Real>: the thesis's SPH fluid as a solver (sections 2.1 and 4;
// the Solver seam: force/solver.hpp).
//
// Two neighbour searches (SphParameters::neighbour_search), the same physics:
//  - Grid (the default): a view of the simulation's particle order
//    (spatial/particle_order.hpp), which this solver asks for: cells of side
//    h + skin, in row-major or Morton order (sph.grid.cell_order), every field
//    moved into that order by the simulation, once per step for every solver
//    ("forces.sort"); then density and pressure, then the forces, each
//    computed on the fly over the 27 cells (9 contiguous ranges in row order,
//    up to 27 in Morton order) around each particle, with explicit SIMD
//    (sph/grid_passes.hpp)                       ("forces.density", "forces.sph")
//    With a Verlet skin (sph.grid.skin > 0) the order is kept, and the sort
//    skipped, until a particle moved more than skin/2 since the last sort.
//    Particles spread over more than 2^21 cells in an axis fall back to the
//    hash for that evaluation.
//  - Hash: the thesis's path, unchanged.
//
// Time-step conditions (h the kernel support radius; c the sound speed; μ the
// dynamic viscosity; SI units), with the constants of StepConditions:
//   CFL       Δt ≤ C_cfl · h / (c + |v|max)           (Monaghan 1992)
//   force     Δt ≤ C_force · sqrt(h / |a|max)          (Monaghan 1992)
//   viscous   Δt ≤ C_visc · h² · ρ_min / μ             (Morris et al. 1997: h²/ν with ν = μ/ρ)
// |a| is the total acceleration (every solver), |v| the speed.
//
// Each force evaluation of the hash path:
//  1. builds the spatial hash of the positions                  ("forces.hash")
//  2. finds every particle's neighbours (r < h) into interaction lists and,
//     as soon as a particle's list is complete, its density and pressure
//     (Algorithm 4)                                              ("forces.search")
//        ρ_i = Σ_j m_j W_poly6(r_ij) + m_i W_poly6(0)             (eq. 2.3, 2.11)
//        p_i = c² (ρ_i − ρ0)                                       (eq. 2.9)
//              (or max(0, ·) with NegativePressure::Zero, see below)
//  3. sums the forces over the lists (Algorithm 5)                ("forces.sph")
//        f_i = −Σ_j m_j (p_i + p_j) / (2 ρ_j) ∇W_spiky(r_ij)        (eq. 2.8)
//              (or without the ½ with PressureForm::Consistent, see below)
//            + μ Σ_j m_j (v_j − v_i) / ρ_j ∇²W_viscosity(r_ij)      (eq. 2.10)
//        a_i += f_i / ρ_i                                          (eq. 2.6)
// External forces (gravity) are separate force models (eq. 2.7).
//
// Eq. 2.8 (Müller et al. 2003's symmetrisation) estimates only half of ∇p:
// on a lattice Σ_j V_j ½(p_i + p_j) ∇W_ij = ½ Σ_j V_j p_j ∇W_ij = ½ ∇p, because
// Σ_j V_j ∇W_ij vanishes. A fluid run with it behaves as if its pressure were
// p/2, and in hydrostatic equilibrium dp/dz = 2 ρ0 g (tested). That is the
// thesis's physics and the default; PressureForm::Consistent drops the ½, so
// that p is the physical pressure (equivalent to the thesis's with c² doubled).
//
// Eq. 2.9 lets pressure go negative where a free surface or a wall leaves a
// particle short of neighbours; with the mixed kernels (poly6 density, spiky
// force) that tension is not energy-conserving, and a free drop clumps into
// groups of particles at rest density and falls apart (seen in tests; the
// "tensile instability"). NegativePressure::Zero clamps it, as many graphics
// codes do; the default keeps the thesis's equation.
//
// With sph.method = "dfsph" (divergence-free SPH, sph/dfsph_stepper.hpp) the
// solver adds no pressure force: each evaluation computes ρ_i and the DFSPH
// factor α_i (sph/dfsph_passes.hpp) on the grid, and the stepper, which owns
// the pressure solves, calls the passes below (density_change,
// pressure_velocity, add_viscosity) on the same grid view while the positions
// stay put. Its warm starts are two internal particle fields (kKappaField,
// kKappaVField), so reorders and checkpoints carry them. Its time-step
// condition is a CFL without a sound speed: Δt ≤ C·h/|v|max (sph.dfsph.cfl).
// DFSPH's non-pressure terms beyond the viscosity (docs/sph.md; 0 = off):
// the XSPH velocity filter (sph.xsph = ε, apply_xsph(), once per step on the
// final velocities), and Akinci et al. 2013's surface tension (sph.surface_
// tension = γ: cohesion and curvature from the normals n_i = h Σ_j (m_j/ρ_j)
// ∇W_ij) and adhesion to boundary particles (sph.adhesion = β), accelerations
// added with the viscosity (add_non_pressure()); sph/dfsph_passes.hpp has
// the formulas. The thesis's solver refuses them.
//
// Boundary particles (Akinci et al. 2012, "Versatile rigid-fluid coupling for
// incompressible SPH"; core/particle_kind.hpp): when the particle set has the
// integer field "kind", its boundary particles (kind 1, static, one layer at
// the fluid's spacing) enter the fluid's sums with the volume weight
//   ψ_b = ρ0 / Σ_k W_bk      (k: the boundary particles within h of b, b included)
// in place of a mass, computed with the density kernel at the first
// evaluation and stored in the boundary particle's mass field (static
// boundaries: once; the flag travels in the solver's state, so a resume does
// not recompute it). Then for a fluid particle i
//   ρ_i += Σ_b ψ_b W_ib
// and the pressure force is mirrored onto the wall. For DFSPH (sph/
// dfsph_passes.hpp) as Akinci and SPlisHSPlasH do it: the pair (i, b) adds the
// fluid particle's own term ψ_b (κ_i/ρ_i) ∇W_ib (κ/ρ = p/ρ²), to ρ, α and the
// pressure passes alike. For the thesis's solver, whose pair law is
// (p_i V_j + p_j V_j) with V = m/ρ, the boundary particle gets V_b = ψ_b/ρ0 and
// the pressure p_b = Σ_f p_f W_bf / Σ_f W_bf, the Shepard average of the fluid
// pressures around it (Adami et al. 2012's wall pressure without its
// hydrostatic term): where the pressure is uniform the pair pushes with
// 2 p_i V_b, as a fluid particle mirrored across the wall would. (The fluid's
// own term alone, p_i V_b, let a particle of the dam break through a thin
// plate at t = 0.38 s: the normal push of a sheet vanishes in its plane, and
// the weakly compressible fluid behind squeezed it there.) These are per-
// particle entries written between the density and the force pass, so the
// SIMD force pass and its scalar twin run unchanged. The viscosity treats a
// boundary particle as a neighbour of volume ψ_b/ρ0 moving with its velocity
// v_b (no-slip walls; v_b = 0 for static ones).
// Moving obstacles (boundary/moving_boundaries.hpp; set_moving_boundaries()):
// the simulation puts their particles at the prescribed x_b and v_b before each
// evaluation, and every pass already reads v_b where a wall's velocity matters
// (DFSPH's Dρ/Dt = Σ_j m_j (v_i − v_j)·∇W_ij, the viscosity, boundary_forces()).
// ψ_b is then recomputed at every evaluation, over all boundary particles:
// rigid motion keeps an obstacle's own sum, but where it passes another
// obstacle or the walls their mutual terms come and go, and Akinci's ψ counts
// every boundary neighbour (one gather over the boundary particles per
// evaluation; static boundary particles far from the moving ones get their
// same value back).
// A boundary particle's own density is reported as ρ0 and its pressure as 0
// (DFSPH) or p_b (the thesis's); the fluid's diagnostics and the DFSPH errors
// count fluid particles only. Boundary particles need the grid search.
//
// On several ranks (a context with ranks: dist/rank_order.hpp) each rank
// computes its own particles among ghosts from the others (dist/halo.hpp,
// sph/halo_passes.hpp), and every particle gets the one-rank bits:
//  - the thesis's solver: exchange 1 (position, velocity, mass, and the kind
//    with boundary particles), the density pass, exchange 2 (ρ, p); with
//    boundary particles ψ_b of the own ones at the first evaluation, then the
//    ghosts' masses (exchange 2 of mass), and after the density pass the own
//    p_b from the ghosts' fluid pressures, then ρ and p again so that the
//    ghosts' p_b are their owners'; the forces;
//  - DFSPH: the evaluation builds a local set (own particles among ghosts)
//    that the stepper's passes use until the next evaluation; each pass first
//    refreshes what it reads of the ghosts (velocities, κ/ρ), and the solves'
//    errors are the one-rank block-order sums (block_sum, dist/block_sum.hpp);
//  - the walls' reaction (boundary_forces(), DFSPH's recorded density-solve
//    reaction): each rank's own boundary particles among their ghosts, sent
//    again through the last evaluation's halo (with_ghosts()).
// The hash search is refused there (distributed_support()).
//
// Units: SI. h in m, ρ0 in kg/m³, c in m/s, μ in Pa·s.
// Every pass gathers into particle i only: deterministic for any thread count.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sph/dfsph_passes.hpp"
#include "swirl/dist/block_sum.hpp"
#include "swirl/dist/rank_order.hpp"
#include "swirl/sph/grid_passes.hpp"
#include "swirl/sph/halo_passes.hpp"
#include "swirl/sph/laws.hpp"
#include "swirl/sph/parameters.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/particle_order.hpp"
#include "swirl/spatial/spatial_hash.hpp"

namespace swirl::sph {

// The constants of the SPH time-step conditions (header); defaults are the usual ones.
struct StepConditions {
  double cfl = 0.6;               // C_cfl
  double force_factor = 0.4;      // C_force
  double viscous_factor = 0.125;  // C_visc
};

template <class Real>
class SphFluid final : public Solver<Real> {
 public:
  explicit SphFluid(const SphParameters& params, const StepConditions& conditions = {})
      : params_(params), conditions_(conditions) {
    if (!(params.smoothing_length > 0) || !std::isfinite(params.smoothing_length))
      throw std::invalid_argument("SPH: smoothing length must be finite and > 0");
    if (!(params.rest_density > 0)) throw std::invalid_argument("SPH: rest density must be > 0");
    if (!(params.sound_speed > 0)) throw std::invalid_argument("SPH: sound speed must be > 0");
    if (!(params.viscosity >= 0)) throw std::invalid_argument("SPH: viscosity must be ≥ 0");
    if (dfsph() && params.neighbour_search != NeighbourSearch::Grid)
      throw std::invalid_argument("SPH: sph.method = \"dfsph\" needs sph.neighbour_search = \"grid\"");
    if (!dfsph() && params.kernel != SphKernel::Thesis)
      throw std::invalid_argument("SPH: sph.kernel = \"cubic_spline\" needs sph.method = \"dfsph\"");
    if (!(params.xsph >= 0 && params.xsph <= 1)) throw std::invalid_argument("SPH: sph.xsph must be in [0, 1]");
    if (!(params.surface_tension >= 0) || !std::isfinite(params.surface_tension))
      throw std::invalid_argument("SPH: sph.surface_tension must be finite and ≥ 0");
    if (!(params.adhesion >= 0) || !std::isfinite(params.adhesion))
      throw std::invalid_argument("SPH: sph.adhesion must be finite and ≥ 0");
    if (!dfsph() && (params.xsph > 0 || params.surface_tension > 0 || params.adhesion > 0))
      throw std::invalid_argument(
          "SPH: sph.xsph, sph.surface_tension and sph.adhesion need sph.method = \"dfsph\"");
  }

  // DFSPH's warm starts: the κ sums of the last constant-density and
  // divergence-free solves (m²/s², κ = p/ρ), per particle.
  static constexpr std::string_view kKappaField = "dfsph_kappa";
  static constexpr std::string_view kKappaVField = "dfsph_kappa_v";

  bool dfsph() const { return params_.method == SphMethod::Dfsph; }

  void declare_fields(ParticleSet<Real>& p) override {
    if (!dfsph()) return;
    p.add_field(std::string(kKappaField), 1, FieldUse::Internal);
    p.add_field(std::string(kKappaVField), 1, FieldUse::Internal);
  }

  std::string_view name() const override { return "sph"; }

  spatial::OrderRequest order_request() const override {
    if (params_.neighbour_search != NeighbourSearch::Grid) return {};
    const double skin = params_.grid_skin;
    return {true, spatial::SortedCellGrid<Real>::cell_length_for(params_.smoothing_length, skin), 0.5 * skin,
            params_.cell_order};
  }

  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
    ranks_ = ctx.ranks;
    if (ctx.ranks) {
      if (dfsph())
        dfsph_evaluate_ranks(p, ctx);
      else
        add_acceleration_ranks(p, ctx);
      return;
    }
    if (dfsph()) {
      dfsph_evaluate(p, ctx);
      return;
    }
    if (params_.neighbour_search == NeighbourSearch::Grid && add_acceleration_grid(p, ctx)) return;
    add_acceleration_hash(p, ctx);
    count_evaluation();
  }

  ScanNeeds scan_needs() const override { return {params_.viscosity > 0, false}; }

  void add_limits(const StepScan& scan, std::size_t /*n*/, std::vector<StepLimit>& out) const override {
    const double h = params_.smoothing_length, speed = std::sqrt(scan.speed2), accel = std::sqrt(scan.accel2);
    if (dfsph()) {
      // Incompressible: no sound speed; a particle moves at most C·h per step.
      if (speed > 0) out.push_back({"cfl", params_.dfsph.cfl * h / speed, scan.speed_at, speed, "|v|"});
    } else {
      out.push_back({"cfl", conditions_.cfl * h / (params_.sound_speed + speed), scan.speed_at, speed, "|v|"});
    }
    if (accel > 0) out.push_back({"force", conditions_.force_factor * std::sqrt(h / accel), scan.accel_at, accel, "|a|"});
    if (params_.viscosity > 0 && scan.density_at != kNoParticle)
      out.push_back({"viscous", conditions_.viscous_factor * h * h * scan.density / params_.viscosity, scan.density_at,
                     scan.density, "ρ"});
  }

  LimitText explain(const StepLimit& l, std::string_view id) const override {
    const double h = params_.smoothing_length;
    if (l.condition == "cfl" && dfsph())
      return {fmt::format("DFSPH's CFL condition C·h/|v|max = {}·{:.3g}/{:.3g} = {:.6g} (|v|max = {:.3g} at particle id {})",
                          params_.dfsph.cfl, h, l.value, l.dt, l.value, id),
              "or a smaller sph.dfsph.cfl with dt = \"adaptive\""};
    if (l.condition == "cfl")
      return {fmt::format("the CFL condition C_cfl·h/(c + |v|max) = {}·{:.3g}/({:.3g} + {:.3g}) = {:.6g} "
                          "(|v|max = {:.3g} at particle id {})",
                          conditions_.cfl, h, params_.sound_speed, l.value, l.dt, l.value, id),
              "or a larger smoothing length h"};
    if (l.condition == "force")
      return {fmt::format("the force condition C_force·sqrt(h/|a|max) = {}·sqrt({:.3g}/{:.3g}) = {:.6g} "
                          "(|a|max = {:.3g} at particle id {})",
                          conditions_.force_factor, h, l.value, l.dt, l.value, id),
              "or a larger smoothing length h; if the fluid is exploding, a larger sound speed c"};
    return {fmt::format("the viscous condition C_visc·h²·ρ/μ = {}·{:.3g}²·{:.3g}/{:.3g} = {:.6g} "
                        "(ρ = {:.3g} at particle id {})",
                        conditions_.viscous_factor, h, l.value, params_.viscosity, l.dt, l.value, id),
            "or a smaller viscosity"};
  }

  std::string advice() const override {
    if (dfsph()) return "if the fluid is exploding, a smaller time step or tighter sph.dfsph tolerances";
    return "if the fluid is exploding, a larger smoothing length h or sound speed c";
  }

  // ---- DFSPH (sph/dfsph_stepper.hpp): passes on the last evaluation's grid ----
  // and on the pairs it kept (sph/dfsph_pairs.hpp: the solves' two passes).
  // Valid between an evaluation and the next position change.
  const DfsphKernel<Real>& dfsph_kernel() const { return *kernel_; }
  // On several ranks (after an evaluation there) p holds this rank's own
  // particles and each pass runs on the evaluation's local set (own particles
  // among their ghosts, dfsph_evaluate_ranks): it copies in what the stepper
  // changed since (velocities, κ/ρ, accelerations), refreshes the ghosts' copy
  // of what the pass reads of them (exchange 2), and copies the own results back.
  // α_i of the last evaluation (sorted order), for every particle of p.
  const Real* factor() const { return alpha_.data() + (ranks_ ? own_.begin : 0); }
  void density_change(const ParticleSet<Real>& p, Real* out, std::size_t block_size) {
    if (!ranks_) {
      dfsph_density_change(pairs_, p, block_size, out, kinds(p), detail::all_of(p), kernel_path());
      return;
    }
    to_local(p.velocity, local_.velocity);
    halo_.refresh(ranks_->comm(), local_, {"velocity"});
    local_out_.resize(local_.size());
    dfsph_density_change(pairs_, local_, block_size, local_out_.data(), kinds(local_), own_, kernel_path());
    std::copy_n(local_out_.data() + own_.begin, p.size(), out);
  }
  void pressure_velocity(ParticleSet<Real>& p, const Real* k_over_rho, Real dt, std::size_t block_size) {
    if (!ranks_) {
      dfsph_pressure_velocity(pairs_, p, block_size, k_over_rho, dt, kinds(p), detail::all_of(p), kernel_path());
      return;
    }
    AlignedVector<Real>& kr = local_.extra(kr_field_);
    std::copy_n(k_over_rho, p.size(), kr.data() + own_.begin);
    halo_.refresh(ranks_->comm(), local_, {std::string(kLocalKappaField)});
    to_local(p.velocity, local_.velocity);
    dfsph_pressure_velocity(pairs_, local_, block_size, kr.data(), dt, kinds(local_), own_, kernel_path());
    from_local(local_.velocity, p.velocity);
  }
  // The non-pressure force of the fluid: the thesis's viscosity (eq. 2.10).
  void add_viscosity(ParticleSet<Real>& p, std::size_t block_size) {
    if (!(params_.viscosity > 0)) return;
    if (!ranks_) {
      dfsph_add_viscosity(grid_, p, SphLaws<Real>(params_), block_size, kinds(p));
      return;
    }
    to_local(p.velocity, local_.velocity);
    halo_.refresh(ranks_->comm(), local_, {"velocity"});
    to_local(p.acceleration, local_.acceleration);
    dfsph_add_viscosity(grid_, local_, SphLaws<Real>(params_), block_size, kinds(local_), own_);
    from_local(local_.acceleration, p.acceleration);
  }
  // DFSPH's non-pressure acceleration of the fluid at the current state (x,
  // ρ and the grid of the last evaluation, the current v), added into a: the
  // viscosity, then surface tension and adhesion (Akinci et al. 2013,
  // sph/dfsph_passes.hpp): one pass for the normals n_i (when γ > 0), one for
  // the forces.
  void add_non_pressure(ParticleSet<Real>& p, std::size_t block_size) {
    add_viscosity(p, block_size);
    const double gamma = params_.surface_tension, beta = params_.adhesion;
    if (!(gamma > 0) && !(beta > 0)) return;
    const Real rho0 = Real(params_.rest_density);
    if (!ranks_) {
      for (auto& a : normals_) a.assign(p.size(), Real(0));
      Real* const n[3] = {normals_[0].data(), normals_[1].data(), normals_[2].data()};
      if (gamma > 0) dfsph_surface_normals(grid_, p, *kernel_, block_size, n, kinds(p));
      dfsph_add_surface_forces(grid_, p, *kernel_, block_size, Real(gamma), Real(beta), rho0, n, kinds(p));
      return;
    }
    Real* const n[3] = {local_.extra(normal_field_, 0).data(), local_.extra(normal_field_, 1).data(),
                        local_.extra(normal_field_, 2).data()};
    if (gamma > 0) {
      dfsph_surface_normals(grid_, local_, *kernel_, block_size, n, kinds(local_), own_);
      halo_.refresh(ranks_->comm(), local_, {std::string(kLocalNormalField)});
    }
    to_local(p.acceleration, local_.acceleration);
    dfsph_add_surface_forces(grid_, local_, *kernel_, block_size, Real(gamma), Real(beta), rho0, n, kinds(local_), own_);
    from_local(local_.acceleration, p.acceleration);
  }
  // DFSPH's XSPH filter (sph.xsph = ε > 0), once per step on the final
  // velocities: v_i += Δv_i of dfsph_xsph_change, all Δv from the velocities
  // before (so momentum is conserved to rounding). Nothing when ε = 0.
  void apply_xsph(ParticleSet<Real>& p, std::size_t block_size) {
    const Real epsilon = Real(params_.xsph);
    if (!(epsilon > 0)) return;
    const ParticleSet<Real>& at = ranks_ ? local_ : p;
    if (ranks_) {
      to_local(p.velocity, local_.velocity);
      halo_.refresh(ranks_->comm(), local_, {"velocity"});
    }
    for (auto& a : normals_) a.resize(at.size());  // scratch: Δv
    Real* const dv[3] = {normals_[0].data(), normals_[1].data(), normals_[2].data()};
    const IndexRange range = ranks_ ? own_ : detail::all_of(p);
    dfsph_xsph_change(grid_, at, *kernel_, block_size, epsilon, dv, kinds(at), range);
    parallel::for_blocks_pinned("dfsph_xsph_apply", p.size(), block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (int axis = 0; axis < 3; ++axis) {
        Real* v = p.velocity[axis].data();
        const Real* d = dv[axis] + range.begin;
#pragma omp simd
        for (std::size_t i = b; i < e; ++i) v[i] += d[i];
      }
    });
  }
  // True when the last evaluation ran on several ranks.
  bool on_ranks() const { return ranks_ != nullptr; }
  // Σ of one value per particle of p, in the one-rank run's block order
  // (parallel::reduce_blocks with block_size, summing from 0): on several
  // ranks the one-rank bits (dist/block_sum.hpp), collective; on one rank the
  // local sum in that order.
  double block_sum(std::span<const double> values, std::size_t block_size) const {
    if (!ranks_) return dist::block_ordered_sum(dist::Communicator::world(), 0, values, block_size);
    return dist::block_ordered_sum(ranks_->comm(), ranks_->first_global_index(), values, block_size);
  }

  // DFSPH: record, after every constant-density solve, the reaction of its
  // impulse on the boundary particles (record_density_reaction()), so that
  // boundary_forces() has it exactly. Off by default (it costs a gather over
  // the boundary particles per step); probes.csv with obstacle forces turns
  // it on before the first step. Changes nothing in the simulation.
  void record_boundary_reactions(bool on) { record_reactions_ = on; }

  // Some boundary particles move (header): ψ_b is recomputed at every
  // evaluation instead of once. Before the first evaluation.
  void set_moving_boundaries(bool on) { moving_boundaries_ = on; }
  bool moving_boundaries() const { return moving_boundaries_; }
  bool records_boundary_reactions() const { return record_reactions_ && dfsph(); }

  // DFSPH, right after the constant-density solve (x, ρ and the grid still
  // those of the step's start, κ the solve's final one): the reaction of the
  // walls' part of its impulse, F_b = Σ_j m_j ψ_b (κ_j/ρ_j) ∇W_jb (the
  // solve's velocity change of j is linear in κ, so this is the sum over its
  // iterations and its warm start), kept by id until the next step. On
  // several ranks collective: each rank records its own boundary particles
  // among their ghosts (exchange 1 of x, m, ρ, κ, kind); a record whose
  // particle moves to another rank at the next sort follows it there when
  // boundary_forces() asks (settle_reactions()).
  void record_density_reaction(const ParticleSet<Real>& p, std::size_t block_size) {
    if (!kinds(p) || !kernel_) return;
    if (p.find_field(kKappaField) == ParticleSet<Real>::npos)
      throw std::logic_error("SPH: the constant-density solve's κ is not declared");
    std::vector<double> f;
    auto record = [&](const ParticleSet<Real>& set, IndexRange own) {
      f.assign(3 * std::size_t(own.end - own.begin), 0.0);
      density_reaction_on(set, own, block_size, f.data());
      const std::int32_t* kind = kinds(set);
      reactions_.clear();
      for (std::size_t i = own.begin; i < own.end; ++i)
        if (is_boundary(kind[i])) {
          const std::size_t at = 3 * (i - own.begin);
          reactions_.push_back({std::uint64_t(set.id[i]), {f[at], f[at + 1], f[at + 2]}});
        }
      std::sort(reactions_.begin(), reactions_.end(),
                [](const Reaction& a, const Reaction& b) { return a.id < b.id; });
    };
    if (!ranks_) {
      record(p, detail::all_of(p));
      return;
    }
    with_ghosts(p, {"position", "mass", "density", std::string(kKindField), std::string(kKappaField)}, block_size,
                record);
  }

  // The force the fluid exerts on each boundary particle (N; docs/sph.md,
  // Probes), into f[3i], f[3i+1], f[3i+2] (0 for a fluid particle): the
  // reaction of the pair law on the fluid particles j within h,
  //   F_b = −Σ_j m_j a_j←b,
  // evaluated on the current state with the grid of the last evaluation
  // (between steps x, ρ, p are that evaluation's; the viscosity uses the
  // current v). The thesis's solver: a_j←b = norm_p (p_j + p_b) V_b (h − r)²/r
  // r⃗_jb / ρ_j + norm_μ V_b (h − r)(v_b − v_j) / ρ_j, V_b = ψ_b/ρ0 (without the
  // gradient correction, when that is on). DFSPH: the last step's pressure
  // impulses over Δt, a_j←b = −ψ_b (κ_j/ρ_j) ∇W_jb: the divergence-free
  // solve's κ^v at the current x, and the constant-density solve's as recorded
  // at the step's start (record_boundary_reactions(); when it is off, its κ
  // taken at the current x, an approximation); plus the same viscosity. A
  // gather into b over the grid: the same bits for any thread count. Needs a
  // grid evaluation (boundary particles always have one).
  // On several ranks (p: this rank's particles) collective, every rank
  // calling it between the same steps: each rank's own boundary particles
  // among their ghosts (exchange 1 of what the sum reads, with the current
  // velocities, through the last evaluation's halo, so the grid's ranges are
  // its ranges again), the one-rank bits for every particle.
  void boundary_forces(const ParticleSet<Real>& p, std::size_t block_size, std::vector<double>& f) {
    f.assign(3 * p.size(), 0.0);
    if (!kinds(p)) return;
    if (!ranks_ && p.empty()) return;
    if (!used_grid_ || (dfsph() && !kernel_))
      throw std::logic_error("SPH: boundary forces before an evaluation on the grid");
    if (dfsph() && (p.find_field(kKappaField) == ParticleSet<Real>::npos ||
                    p.find_field(kKappaVField) == ParticleSet<Real>::npos))
      throw std::logic_error("SPH: boundary forces without DFSPH's κ fields");
    if (!ranks_) {
      boundary_forces_on(p, detail::all_of(p), block_size, f.data());
      return;
    }
    if (records_boundary_reactions()) settle_reactions(p);
    std::vector<std::string> fields{"position", "velocity", "mass", "density", "pressure", std::string(kKindField)};
    if (dfsph()) fields.insert(fields.end(), {std::string(kKappaField), std::string(kKappaVField)});
    with_ghosts(p, fields, block_size, [&](const ParticleSet<Real>& set, IndexRange own) {
      boundary_forces_on(set, own, block_size, f.data());
    });
  }

  // The particles' kinds (core/particle_kind.hpp), or null when all are fluid.
  static const std::int32_t* kinds(const ParticleSet<Real>& p) {
    const std::size_t k = p.find_int_field(kKindField);
    return k == ParticleSet<Real>::npos ? nullptr : p.int_field(k).data();
  }
  // Fluid particles (not boundary) as of the last evaluation: what averages
  // over the fluid divide by (on several ranks: of all ranks).
  std::size_t fluid_count(const ParticleSet<Real>& p) const {
    if (kinds(p)) return fluid_count_;
    return ranks_ ? static_cast<std::size_t>(ranks_->global_count()) : p.size();
  }
  // Boundary particles in the set (0 without the kind field; one rank).
  std::size_t boundary_count(const ParticleSet<Real>& p) const { return kinds(p) ? p.size() - fluid_count_ : 0; }

  std::vector<std::string> diagnostic_columns() const override {
    return {"mean_density_error", "max_density_error", "mean_neighbours"};
  }
  // Mean and largest |ρ − ρ0|/ρ0 over the fluid (in the one-rank block
  // order: the same bits for any thread and rank count), and the last
  // evaluation's mean neighbour count.
  void add_diagnostics(const ParticleSet<Real>& p, const dist::BlockFold& fold,
                       std::vector<double>& row) const override {
    using dist::FoldOp;
    const double rho0 = params_.rest_density;
    const std::int32_t* kind = kinds(p);
    // The error's sum and maximum, and the fluid particles counted.
    const auto e = fold("sph_diagnostics", p.size(), std::array{FoldOp::Sum, FoldOp::Max, FoldOp::Sum},
                        [&](std::size_t i, std::array<double, 3>& c) {
                          if (kind && is_boundary(kind[i])) return false;  // the fluid's error only
                          const double error = std::abs(double(p.density[i]) - rho0) / rho0;
                          c = {error, error, 1.0};
                          return true;
                        });
    row.insert(row.end(), {e[2] == 0 ? 0.0 : e[0] / e[2], e[1], mean_neighbours_});
  }
  // Viscosity dissipates, and the equation of state's elastic energy is not counted.
  bool conserves_energy() const override { return false; }
  void add_metrics(NamedValues& out) const override {
    out.emplace_back("mean_neighbours", evaluations_ > 0 ? neighbour_sum_ / double(evaluations_) : mean_neighbours_);
  }
  // The ghosts over the rank's own particles, summed over this run's evaluations.
  void add_rank_metrics(NamedValues& out) const override {
    out.emplace_back("halo_ghosts_per_particle", halo_owned_sum_ > 0 ? halo_ghost_sum_ / halo_owned_sum_ : 0.0);
  }
  void save_state(NamedValues& out) const override {
    out.emplace_back("sph.neighbour_sum", neighbour_sum_);
    out.emplace_back("sph.evaluations", double(evaluations_));
    if (boundary_volumes_) out.emplace_back("sph.boundary_volumes", 1.0);
  }
  void load_state(const NamedValues& values) override {
    neighbour_sum_ = find_value(values, "sph.neighbour_sum").value_or(0.0);
    evaluations_ = static_cast<std::uint64_t>(find_value(values, "sph.evaluations").value_or(0.0));
    boundary_volumes_ = find_value(values, "sph.boundary_volumes").value_or(0.0) != 0;
  }

  // The evaluations counted for the summary's mean neighbour count (state).
  // DfsphStepper's re-evaluation after a resume puts them back, so that it
  // counts as the uninterrupted run's evaluation it repeats.
  struct EvaluationTally {
    double neighbour_sum = 0;
    std::uint64_t evaluations = 0;
  };
  EvaluationTally tally() const { return {neighbour_sum_, evaluations_}; }
  void set_tally(const EvaluationTally& t) {
    neighbour_sum_ = t.neighbour_sum;
    evaluations_ = t.evaluations;
  }

  // Interaction lists of the last evaluation (one row per particle; hash search
  // only: the grid computes on the fly and leaves them empty).
  const spatial::NeighbourList<Real>& lists() const { return lists_; }
  // Mean neighbours per particle in the last evaluation (self excluded).
  double mean_neighbours() const { return mean_neighbours_; }
  const spatial::SpatialHash<Real>& hash() const { return hash_; }
  const spatial::SortedCellGrid<Real>& grid() const { return grid_; }
  const SphParameters& parameters() const { return params_; }
  // A new viscosity μ (≥ 0) from the next evaluation on (swirl view's slider;
  // call Simulation::parameters_changed() after it, between steps).
  void set_viscosity(double mu) {
    if (!(mu >= 0) || !std::isfinite(mu)) throw std::invalid_argument("SPH: viscosity must be finite and ≥ 0");
    params_.viscosity = mu;
  }
  // On ranks: each fluid particle's neighbour candidates in the last
  // evaluation (grid_candidates); a boundary particle adds nothing, being
  // skipped as a particle by the passes that dominate (the base cost per
  // particle is dist::RankOrder's).
  void add_rank_costs(std::span<std::uint64_t> costs) const override {
    if (rank_costs_.size() != costs.size()) return;
    for (std::size_t i = 0; i < costs.size(); ++i) costs[i] += rank_costs_[i];
  }

  // Empty when these parameters run on several ranks; otherwise what does not (yet).
  std::string distributed_support() const {
    if (params_.neighbour_search != NeighbourSearch::Grid) return "sph.neighbour_search = \"hash\"";
    return {};
  }

  // True when the last evaluation used the sorted grid.
  bool used_grid() const { return used_grid_; }
  const StepConditions& conditions() const { return conditions_; }
  // Bytes the solver keeps between evaluations (search structures, lists,
  // scratch), in all: add to the particle fields for the memory per particle.
  std::size_t scratch_bytes() const override {
    return grid_.bytes() + scratch_.bytes() + alpha_.capacity() * sizeof(Real) + pairs_.bytes() +
           (normals_[0].capacity() + normals_[1].capacity() + normals_[2].capacity()) * sizeof(Real) +
           lists_.row_particle.capacity() * sizeof(std::uint32_t) + lists_.offsets.capacity() * sizeof(std::size_t) +
           lists_.neighbour.capacity() * sizeof(std::uint32_t) + lists_.r2.capacity() * sizeof(Real) +
           hash_.cells().capacity() * (2 * sizeof(spatial::Cell) + sizeof(std::uint32_t) + 3 * sizeof(Real)) +
           hash_.offsets().capacity() * sizeof(std::uint32_t) + hash_.order().capacity() * sizeof(std::uint32_t) +
           hash_.neighbour_hashes().capacity() * sizeof(std::uint32_t) + local_bytes();
  }

 private:
  // A recorded density-solve reaction (record_density_reaction()): a boundary particle's id and F_b.
  struct Reaction {
    std::uint64_t id = 0;
    std::array<double, 3> force{};
  };

  // record_density_reaction()'s sum for the particles own of `set` (the grid
  // of the last evaluation indexes `set`), into out[3(i − own.begin)...].
  void density_reaction_on(const ParticleSet<Real>& set, IndexRange own, std::size_t block_size, double* out) const {
    const std::int32_t* kind = kinds(set);
    const std::size_t k1 = set.find_field(kKappaField);
    const Real *x = set.position.x.data(), *y = set.position.y.data(), *z = set.position.z.data(), *m = set.mass.data();
    const Real *rho = set.density.data(), *kappa = set.extra(k1).data();
    const std::size_t from = own.begin;
    parallel::for_blocks_pinned("sph_boundary_reaction", own.end - own.begin, block_size,
                                [&](std::size_t b, std::size_t e, std::size_t) {
      detail::for_each_in_cells(grid_, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
        if (!is_boundary(kind[i])) return;
        double fx = 0, fy = 0, fz = 0;
        detail::for_each_pair(x, y, z, i, ranges, count, kernel_->h2, [&](std::size_t j, Real, Real, Real, Real r2) {
          if (is_boundary(kind[j])) return;
          const double dx = double(x[j]) - double(x[i]), dy = double(y[j]) - double(y[i]), dz = double(z[j]) - double(z[i]);
          const double r = std::sqrt(double(r2));
          if (!(r > 0)) return;
          const double c = double(m[j]) * double(m[i]) * double(kappa[j]) / double(rho[j]) * double(kernel_->gradient(Real(r)));
          fx += c * dx, fy += c * dy, fz += c * dz;
        });
        const std::size_t at = 3 * (i - from);
        out[at] = fx, out[at + 1] = fy, out[at + 2] = fz;
      });
    });
  }

  // boundary_forces()' sum for the particles own of `set`, into out[3(i − own.begin)...].
  void boundary_forces_on(const ParticleSet<Real>& set, IndexRange own, std::size_t block_size, double* out) const {
    const std::int32_t* kind = kinds(set);
    const SphLaws<Real> laws(params_);
    const double rho0 = params_.rest_density;
    const Real *x = set.position.x.data(), *y = set.position.y.data(), *z = set.position.z.data(), *m = set.mass.data();
    const Real *vx = set.velocity.x.data(), *vy = set.velocity.y.data(), *vz = set.velocity.z.data();
    const Real *rho = set.density.data(), *pr = set.pressure.data();
    const Real *kappa = nullptr, *kappa_v = nullptr;
    if (dfsph()) kappa = set.extra(set.find_field(kKappaField)).data(), kappa_v = set.extra(set.find_field(kKappaVField)).data();
    const double norm_p = double(laws.pressure.norm), norm_v = double(laws.viscosity.norm);
    // Before the first step nothing is recorded, and κ is 0 anyway.
    const bool recorded = records_boundary_reactions();
    const std::size_t from = own.begin;
    parallel::for_blocks_pinned("sph_boundary_forces", own.end - own.begin, block_size,
                                [&](std::size_t b, std::size_t e, std::size_t) {
      detail::for_each_in_cells(grid_, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
        if (!is_boundary(kind[i])) return;
        const double volume = double(m[i]) / rho0;  // V_b = ψ_b/ρ0
        double fx = 0, fy = 0, fz = 0;
        detail::for_each_pair(x, y, z, i, ranges, count, laws.h2, [&](std::size_t j, Real, Real, Real, Real r2) {
          if (is_boundary(kind[j])) return;
          // r⃗_jb = x_j − x_b, in double from the same positions.
          const double dx = double(x[j]) - double(x[i]), dy = double(y[j]) - double(y[i]), dz = double(z[j]) - double(z[i]);
          const double r = std::sqrt(double(r2)), mj = double(m[j]), rj = double(rho[j]);
          const double q = std::max(double(laws.h) - r, 0.0);
          double radial = 0;  // a_j←b = radial · r⃗_jb + viscous · (v_b − v_j)
          if (dfsph()) {
            const double k = double(kappa_v[j]) + (recorded ? 0.0 : double(kappa[j]));
            radial = r > 0 ? -double(m[i]) * k / rj * double(kernel_->gradient(Real(r))) : 0.0;
          } else {
            radial = r > 0 ? norm_p * (double(pr[j]) + double(pr[i])) * volume * q * q / r / rj : 0.0;
          }
          const double viscous = norm_v * volume * q / rj;
          fx -= mj * (radial * dx + viscous * (double(vx[i]) - double(vx[j])));
          fy -= mj * (radial * dy + viscous * (double(vy[i]) - double(vy[j])));
          fz -= mj * (radial * dz + viscous * (double(vz[i]) - double(vz[j])));
        });
        if (recorded) {
          const std::uint64_t id = set.id[i];
          const auto it = std::lower_bound(reactions_.begin(), reactions_.end(), id,
                                           [](const Reaction& r, std::uint64_t v) { return r.id < v; });
          if (it != reactions_.end() && it->id == id)
            fx += it->force[0], fy += it->force[1], fz += it->force[2];
        }
        const std::size_t at = 3 * (i - from);
        out[at] = fx, out[at + 1] = fy, out[at + 2] = fz;
      });
    });
  }

  // On ranks, collective: body(set, own) on a copy of this rank's particles p
  // (as the last evaluation left them in order) among their ghosts, which
  // carry the named fields (the others zero): exchange 1 through that
  // evaluation's halo (kept un-inserted in reaction_halo_), so the local
  // array has the evaluation's layout, and grid_ is that evaluation's view of
  // it. DFSPH keeps its view (over local_'s keys, which have that layout);
  // the thesis's solver took its ghosts out after its passes, which left its
  // view without the keys it reads, so it is made again over this set's (the
  // same frame, keys and global indices: the same view; it is not used again
  // before the next evaluation makes its own).
  template <class Body>
  void with_ghosts(const ParticleSet<Real>& p, const std::vector<std::string>& fields, std::size_t block_size,
                   Body&& body) {
    if (p.size() != reaction_halo_.owned_count())
      throw std::logic_error("SPH: boundary forces on ranks after the particles changed since the evaluation");
    ghost_set_ = p;
    if (dfsph())
      ghost_keys_.assign(halo_keys_.begin() + own_.begin, halo_keys_.begin() + own_.end);
    else
      ghost_keys_ = halo_keys_;
    reaction_halo_.insert(ranks_->comm(), ghost_set_, ghost_keys_, fields);
    if (!dfsph()) grid_.view(ranks_->frame(), ghost_keys_, reaction_halo_.global_index(), block_size);
    body(static_cast<const ParticleSet<Real>&>(ghost_set_), reaction_halo_.owned());
    reaction_halo_.remove(ghost_set_, ghost_keys_);  // ready for another call before the next evaluation
    ghost_set_ = ParticleSet<Real>();
    ghost_keys_ = {};
  }

  // On ranks, collective: the recorded reactions (record_density_reaction(),
  // by id, of the particles each rank held then) to the ranks that hold their
  // particles now: those of particles that left a rank in the sort since are
  // sent to every rank (an all-gather of 32 B each; a boundary particle moves
  // only when a cut passes it), and each keeps those it holds.
  void settle_reactions(const ParticleSet<Real>& p) {
    const std::int32_t* kind = kinds(p);
    std::vector<std::uint64_t> mine;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (is_boundary(kind[i])) mine.push_back(std::uint64_t(p.id[i]));
    std::sort(mine.begin(), mine.end());
    auto held = [&](std::uint64_t id) { return std::binary_search(mine.begin(), mine.end(), id); };
    std::vector<Reaction> kept, left;
    for (const Reaction& r : reactions_) (held(r.id) ? kept : left).push_back(r);
    std::vector<Reaction> moved;
    for (const dist::Bytes& b : ranks_->comm().all_gather(dist::to_bytes(std::span<const Reaction>(left))))
      dist::append_values(b, moved, "SPH: boundary reactions");
    for (const Reaction& r : moved)
      if (held(r.id)) kept.push_back(r);
    std::sort(kept.begin(), kept.end(), [](const Reaction& a, const Reaction& b) { return a.id < b.id; });
    reactions_ = std::move(kept);
  }

  void count_evaluation() {
    neighbour_sum_ += mean_neighbours_;
    ++evaluations_;
  }

  static std::size_t count_fluid(const ParticleSet<Real>& p) { return count_fluid(p, detail::all_of(p)); }
  static std::size_t count_fluid(const ParticleSet<Real>& p, IndexRange only) {
    const std::int32_t* kind = kinds(p);
    std::size_t n = 0;
    for (std::size_t i = only.begin; i < only.end; ++i) n += kind && is_boundary(kind[i]) ? 0 : 1;
    return n;
  }

  // Boundary particles, once the grid view is up: the fluid count, and (once
  // for static boundaries, at every evaluation with moving ones) every boundary particle's ψ_b = ρ0 / Σ_k W_bk over
  // the boundary particles k within h (b included), W the density kernel
  // `w(r², r)`, stored as its mass. Gathers into b only, in the grid's order:
  // the same bits for any thread count, and on a resume (the flag is state).
  // On several ranks (halo: the ghosts are in p) for the own particles `own`
  // alone, the fluid count summed over the ranks, and the ghosts' new masses
  // exchanged (ψ reads only positions and kinds, which exchange 1 brought).
  // Returns true when it computed ψ now.
  template <class W>
  bool prepare_boundary(ParticleSet<Real>& p, std::size_t block_size, W&& w, IndexRange own,
                        dist::Halo* halo = nullptr) {
    const std::int32_t* kind = kinds(p);
    if (!kind) return false;
    // The solves' average errors divide by it. One rank: counted at every
    // evaluation (inlets and outlets change it, sim/inlets_outlets.hpp).
    // Several ranks: summed over them only when their particle count changed
    // (no particle changes kind and inlets and outlets add and remove only
    // fluid: the boundary count is fixed, so the fluid count follows the global
    // count), as
    // the sum is a collective between the ghosts' insert and the density
    // pass, where the ranks' unequal shares of the insert would wait.
    if (!ranks_)
      fluid_count_ = count_fluid(p, own);
    else if (fluid_count_for_ != ranks_->global_count()) {
      fluid_count_ = static_cast<std::size_t>(ranks_->comm().sum(std::uint64_t{count_fluid(p, own)}));
      fluid_count_for_ = ranks_->global_count();
    }
    if (boundary_volumes_ && !moving_boundaries_) return false;
    const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
    Real* m = p.mass.data();
    const Real h2 = Real(params_.smoothing_length * params_.smoothing_length), rho0 = Real(params_.rest_density);
    const std::size_t from = own.begin;
    parallel::for_blocks_pinned("sph_boundary_volume", own.end - own.begin, block_size,
                                [&](std::size_t b, std::size_t e, std::size_t) {
      detail::for_each_in_cells(grid_, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
        if (!is_boundary(kind[i])) return;
        Real sum = 0;
        detail::for_each_pair(x, y, z, i, ranges, count, h2, [&](std::size_t j, Real, Real, Real, Real r2) {
          if (is_boundary(kind[j])) sum += w(r2, std::sqrt(r2));
        });
        m[i] = rho0 / sum;  // sum ≥ W(0) > 0: b itself
      });
    });
    if (halo) halo->refresh(ranks_->comm(), p, {"mass"});
    boundary_volumes_ = true;
    return true;
  }

  // The thesis's passes with boundary particles: after the density pass, a
  // boundary particle's entries are set so that the force pass (scalar or
  // SIMD, unchanged) applies the mirrored pressure of the header: ρ_b = ρ0,
  // V_b = ψ_b/ρ0, and p_b the Shepard average of the fluid's pressures around
  // it, p_b = Σ_f p_f W_bf / Σ_f W_bf (0 with no fluid within h), so that a
  // pair's (p_i + p_b) V_b is the fluid particle's own term doubled where the
  // pressure is uniform, as a mirrored fluid particle would push.
  // `own`: the particles to compute (on ranks: the own ones; the ghosts' fluid
  // pressures must be their owners').
  void mirror_boundary(ParticleSet<Real>& p, std::size_t block_size, const SphLaws<Real>& laws, IndexRange own) {
    const std::int32_t* kind = kinds(p);
    if (!kind) return;
    const std::size_t from = own.begin, todo = own.end - own.begin;
    const Real rho0 = Real(params_.rest_density);
    const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
    Real *rho = p.density.data(), *pr = p.pressure.data(), *V = scratch_.volume.data(), *PV = scratch_.pressure_volume.data();
    // Two passes: the averages read fluid pressures only, then the entries are written.
    boundary_pressure_.resize(p.size());
    Real* pb = boundary_pressure_.data();
    parallel::for_blocks_pinned("sph_boundary_pressure", todo, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      const SphLaws<Real> law = laws;
      detail::for_each_in_cells(grid_, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
        if (!is_boundary(kind[i])) return;
        Real weighted = 0, weights = 0;
        detail::for_each_pair(x, y, z, i, ranges, count, law.h2, [&](std::size_t j, Real, Real, Real, Real r2) {
          if (is_boundary(kind[j])) return;
          const Real w = law.density.term(Real(1), law.gap2(r2));
          weighted += w * pr[j];
          weights += w;
        });
        pb[i] = weights > Real(0) ? weighted / weights : Real(0);
      });
    });
    parallel::for_blocks_pinned("sph_boundary_mirror", todo, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = from + b; i < from + e; ++i) {
        if (!is_boundary(kind[i])) continue;
        rho[i] = rho0;
        pr[i] = pb[i];
        V[i] = m[i] / rho0;
        PV[i] = pb[i] * V[i];
      }
    });
  }

  // The sorted grid (spatial/cell_grid.hpp, sph/grid_passes.hpp): a view of
  // the simulation's order, then density and forces on the fly. Returns
  // false, having done nothing, when the particles spread too far for the grid.
  bool add_acceleration_grid(ParticleSet<Real>& p, const SolverContext<Real>& ctx) {
    if (!ctx.order)
      throw std::logic_error("SPH grid: needs the simulation's particle order (or evaluate_alone())");
    {
      PhaseScope phase(ctx, "forces.cells");
      grid_.set_table(params_.cell_table);
      if (!grid_.view(*ctx.order, ctx.block_size)) return false;
    }
    used_grid_ = true;
    lists_ = {};
    const SphLaws<Real> k(params_);
    prepare_boundary(p, ctx.block_size, density_weight(k), detail::all_of(p));
    std::uint64_t pairs = 0;
    {
      PhaseScope phase(ctx, "forces.density");
      pairs = grid_density(grid_, p, k, ctx.block_size, scratch_, kernel_path());
      mirror_boundary(p, ctx.block_size, k, detail::all_of(p));
    }
    mean_neighbours_ = p.empty() ? 0.0 : static_cast<double>(pairs) / static_cast<double>(p.size());
    count_evaluation();
    if (k.corrected) {
      PhaseScope phase(ctx, "forces.correction");
      grid_gradient_correction(grid_, p, k, ctx.block_size, scratch_);
    }
    {
      PhaseScope phase(ctx, "forces.sph");
      grid_forces(grid_, p, k, ctx.block_size, scratch_, kernel_path());
    }
    return true;
  }

  // The grid passes on this rank's particles among their ghosts (header):
  // exchange 1 before the density pass, exchange 2 inside
  // halo_density_and_forces, the ghosts out again before returning.
  void add_acceleration_ranks(ParticleSet<Real>& p, const SolverContext<Real>& ctx) {
    const dist::RankOrder<Real>& order = *ctx.ranks;
    if (const std::string no = distributed_support(); !no.empty())
      throw std::invalid_argument("SPH on several ranks: " + no + " does not run on several ranks yet");
    if (!order.cells_fit())
      throw std::runtime_error(
          "SPH on several ranks: the particles spread over more than 2^21 grid cells per axis (the one-rank run "
          "falls back to the hash search here, which does not run on ranks); fix: a box with walls");
    const dist::Communicator& comm = order.comm();
    halo_keys_.assign(order.keys().begin(), order.keys().end());
    dist::Halo halo;
    {
      PhaseScope phase(ctx, "forces.halo");
      halo = dist::Halo::find(comm, order.frame(), halo_keys_, order.first_global_index(), order.global_count(),
                              order.cut_keys(), kHaloTail<Real>);
      halo.insert(comm, p, halo_keys_, exchange_fields(p));
      halo_ghost_sum_ += double(halo.ghost_count());
      halo_owned_sum_ += double(halo.owned_count());
    }
    {
      PhaseScope phase(ctx, "forces.cells");
      grid_.set_table(params_.cell_table);
      grid_.view(order.frame(), halo_keys_, halo.global_index(), ctx.block_size);
    }
    used_grid_ = true;
    lists_ = {};
    const SphLaws<Real> k(params_);
    const IndexRange own = halo.owned();
    rank_costs_.assign(own.end - own.begin, 0);  // the density pass counts them (record_rank_costs' figures)
    prepare_boundary(p, ctx.block_size, density_weight(k), own, &halo);
    std::uint64_t pairs = 0;
    {
      PhaseScope phase(ctx, "forces.sph");
      // With boundary particles: p_b from the ghosts' fluid pressures (exchange
      // 2), then the ghosts' p_b (exchange 2 again) before the force pass.
      pairs = halo_density_and_forces(
          comm, halo, grid_, p, k, ctx.block_size, scratch_, kernel_path(),
          [&] {
            if (!kinds(p)) return false;
            mirror_boundary(p, ctx.block_size, k, own);
            return true;
          },
          std::span<std::uint64_t>(rank_costs_));
    }
    zero_boundary_costs(p, own);
    halo.remove(p, halo_keys_);
    if (kinds(p)) reaction_halo_ = std::move(halo);  // boundary_forces()
    // The mean over all particles: an exact integer sum, then the one-rank division.
    const std::uint64_t all = comm.sum(pairs);
    mean_neighbours_ = order.global_count() == 0 ? 0.0 : static_cast<double>(all) / static_cast<double>(order.global_count());
    count_evaluation();
  }

  // DFSPH's evaluation: the grid view, ρ and α; no force (the stepper's solves
  // are the pressure, and it adds the viscosity once the velocities are final).
  void dfsph_evaluate(ParticleSet<Real>& p, const SolverContext<Real>& ctx) {
    if (!ctx.order) throw std::logic_error("DFSPH: needs the simulation's particle order");
    {
      PhaseScope phase(ctx, "forces.cells");
      grid_.set_table(params_.cell_table);
      if (!grid_.view(*ctx.order, ctx.block_size))
        throw std::runtime_error(
            "DFSPH: the particles spread over more than 2^21 grid cells along an axis, which the grid search (the "
            "only one DFSPH has) cannot index; a larger smoothing length or a smaller domain");
    }
    used_grid_ = true;
    lists_ = {};
    if (!kernel_) kernel_.emplace(params_.kernel, Real(params_.smoothing_length));
    prepare_boundary(p, ctx.block_size, [&](Real r2, Real r) { return kernel_->w(r2, r); }, detail::all_of(p));
    const std::int32_t* kind = kinds(p);
    if (!(alpha_cap_ > 0) && !p.empty()) {
      // The cap of α: twice the factor of a full lattice neighbourhood at the
      // spacing s = (m/ρ0)^⅓ of the largest fluid mass (scenes' fluids have one
      // mass; the largest, unlike the first, does not depend on the order;
      // a boundary particle's mass is its ψ).
      double m = 0;
      for (std::size_t i = 0; i < p.size(); ++i)
        if (!kind || !is_boundary(kind[i])) m = std::max(m, double(p.mass[i]));
      const double s = std::cbrt(m / params_.rest_density);
      alpha_cap_ = kAlphaCapFactor * dfsph_lattice_factor(*kernel_, m, s);
    }
    alpha_.resize(p.size());
    std::uint64_t pairs = 0;
    {
      PhaseScope phase(ctx, "forces.density");
      pairs = dfsph_density_and_factor(grid_, p, *kernel_, ctx.block_size, alpha_.data(), Real(alpha_cap_), kind,
                                       Real(params_.rest_density), detail::kAllParticles, &pairs_);
    }
    const std::size_t fluid = fluid_count(p);  // a boundary particle's own pairs are not summed
    mean_neighbours_ = fluid == 0 ? 0.0 : static_cast<double>(pairs) / static_cast<double>(fluid);
    count_evaluation();
  }

  // DFSPH on several ranks: the evaluation of dfsph_evaluate() on a local set
  // of this rank's particles among their ghosts (local_: the fields the DFSPH
  // passes read, exchange 1 of position, velocity, mass and kind), which the
  // stepper's passes use until the next evaluation (density_change, ...);
  // ρ (and ψ when computed now) are copied back to p, α stays local.
  void dfsph_evaluate_ranks(ParticleSet<Real>& p, const SolverContext<Real>& ctx) {
    const dist::RankOrder<Real>& order = *ctx.ranks;
    const dist::Communicator& comm = order.comm();
    if (!order.cells_fit())
      throw std::runtime_error(
          "DFSPH: the particles spread over more than 2^21 grid cells along an axis, which the grid search (the "
          "only one DFSPH has) cannot index; a larger smoothing length or a smaller domain");
    const std::size_t n = p.size();
    {
      PhaseScope phase(ctx, "forces.halo");
      local_ = ParticleSet<Real>(n);
      for (int a = 0; a < 3; ++a) {
        std::copy_n(p.position[a].data(), n, local_.position[a].data());
        std::copy_n(p.velocity[a].data(), n, local_.velocity[a].data());
      }
      std::copy_n(p.mass.data(), n, local_.mass.data());
      std::copy_n(p.id.data(), n, local_.id.data());
      if (const std::int32_t* kind = kinds(p)) {
        const std::size_t k = local_.add_int_field(std::string(kKindField));
        std::copy_n(kind, n, local_.int_field(k).data());
      }
      kr_field_ = local_.add_field(std::string(kLocalKappaField), 1, FieldUse::Internal);
      if (params_.surface_tension > 0 || params_.adhesion > 0)
        normal_field_ = local_.add_field(std::string(kLocalNormalField), 3, FieldUse::Internal);
      halo_keys_.assign(order.keys().begin(), order.keys().end());
      halo_ = dist::Halo::find(comm, order.frame(), halo_keys_, order.first_global_index(), order.global_count(),
                               order.cut_keys(), kHaloTail<Real>);
      if (kinds(p)) reaction_halo_ = halo_;  // before insert(): boundary_forces(), record_density_reaction()
      halo_.insert(comm, local_, halo_keys_, exchange_fields(p));
      halo_ghost_sum_ += double(halo_.ghost_count());
      halo_owned_sum_ += double(halo_.owned_count());
      own_ = halo_.owned();
    }
    {
      PhaseScope phase(ctx, "forces.cells");
      grid_.set_table(params_.cell_table);
      grid_.view(order.frame(), halo_keys_, halo_.global_index(), ctx.block_size);
    }
    used_grid_ = true;
    lists_ = {};
    record_rank_costs(local_, own_, ctx.block_size);
    if (!kernel_) kernel_.emplace(params_.kernel, Real(params_.smoothing_length));
    if (prepare_boundary(local_, ctx.block_size, [&](Real r2, Real r) { return kernel_->w(r2, r); }, own_, &halo_))
      std::copy_n(local_.mass.data() + own_.begin, n, p.mass.data());
    const std::int32_t* kind = kinds(local_);
    if (!(alpha_cap_ > 0) && order.global_count() > 0) {
      // As dfsph_evaluate(): the largest fluid mass, of all ranks (an exact max).
      double m[1] = {0};
      for (std::size_t i = own_.begin; i < own_.end; ++i)
        if (!kind || !is_boundary(kind[i])) m[0] = std::max(m[0], double(local_.mass[i]));
      comm.max(m);
      const double s = std::cbrt(m[0] / params_.rest_density);
      alpha_cap_ = kAlphaCapFactor * dfsph_lattice_factor(*kernel_, m[0], s);
    }
    alpha_.resize(local_.size());
    std::uint64_t pairs = 0;
    {
      PhaseScope phase(ctx, "forces.density");
      pairs = dfsph_density_and_factor(grid_, local_, *kernel_, ctx.block_size, alpha_.data(), Real(alpha_cap_), kind,
                                       Real(params_.rest_density), own_, &pairs_);
      std::copy_n(local_.density.data() + own_.begin, n, p.density.data());
      // The ghosts' ρ: the viscosity's V_j = m_j/ρ_j, XSPH's and surface tension's ρ_j.
      if (params_.viscosity > 0 || params_.xsph > 0 || params_.surface_tension > 0)
        halo_.refresh(comm, local_, {"density"});
    }
    const std::uint64_t all = comm.sum(pairs);
    const std::size_t fluid = fluid_count(p);
    mean_neighbours_ = fluid == 0 ? 0.0 : static_cast<double>(all) / static_cast<double>(fluid);
    count_evaluation();
  }

  // On ranks, after the grid view over this rank's particles among their
  // ghosts (p: that set; own: this rank's range in it): add_rank_costs's figures.
  void record_rank_costs(const ParticleSet<Real>& p, IndexRange own, std::size_t block_size) {
    rank_costs_.assign(own.end - own.begin, 0);
    grid_candidates(grid_, own, block_size, std::span<std::uint64_t>(rank_costs_));
    zero_boundary_costs(p, own);
  }
  void zero_boundary_costs(const ParticleSet<Real>& p, IndexRange own) {
    if (const std::int32_t* kind = kinds(p))
      for (std::size_t i = own.begin; i < own.end; ++i)
        if (is_boundary(kind[i])) rank_costs_[i - own.begin] = 0;
  }

  // DFSPH on ranks: the local set, its keys and a pass's output.
  std::size_t local_bytes() const {
    std::size_t reals = local_out_.capacity(), ints = 0;
    local_.for_each_array([&](const AlignedVector<Real>& a) { reals += a.capacity(); });
    local_.for_each_int_array([&](const auto& a) { ints += a.capacity(); });
    return reals * sizeof(Real) + ints * sizeof(std::int32_t) + local_.id.capacity() * sizeof(local_.id[0]) +
           halo_keys_.capacity() * sizeof(std::uint64_t);
  }
  // What exchange 1 sends: kHaloFields, and the particles' kinds when they have them.
  static std::vector<std::string> exchange_fields(const ParticleSet<Real>& p) {
    std::vector<std::string> fields = kHaloFields;
    if (kinds(p)) fields.emplace_back(kKindField);
    return fields;
  }
  // The thesis's density kernel as prepare_boundary's weight.
  static auto density_weight(const SphLaws<Real>& k) {
    return [k](Real r2, Real) { return k.density.density(k.density.term(Real(1), k.gap2(r2))); };
  }
  // Own particles' values between p (own only) and local_ (own among ghosts).
  void to_local(const Vec3Array<Real>& from, Vec3Array<Real>& to) const {
    for (int a = 0; a < 3; ++a) std::copy(from[a].begin(), from[a].end(), to[a].begin() + own_.begin);
  }
  void from_local(const Vec3Array<Real>& from, Vec3Array<Real>& to) const {
    for (int a = 0; a < 3; ++a)
      std::copy_n(from[a].begin() + own_.begin, to[a].size(), to[a].begin());
  }

  // The thesis's path: spatial hash, lists with density inside the search.
  void add_acceleration_hash(ParticleSet<Real>& p, const SolverContext<Real>& ctx) {
    if (kinds(p))
      throw std::runtime_error(
          "SPH: boundary particles need the grid search (sph.neighbour_search = \"grid\"; the hash path has none, and "
          "the grid fell back to it if the particles spread over more than 2^21 cells along an axis)");
    used_grid_ = false;
    const std::size_t n = p.size();
    const Real h = Real(params_.smoothing_length);
    {
      PhaseScope phase(ctx, "forces.hash");
      hash_.build(p, h, params_.buckets ? params_.buckets : default_bucket_count(n), ctx.block_size,
                  params_.table_build, params_.neighbour_hashes, ctx.timers);
    }
    {
      PhaseScope phase(ctx, "forces.search");
      const SphLaws<Real> laws(params_);
      const Real* m = p.mass.data();
      Real* rho = p.density.data();
      Real* pressure = p.pressure.data();
      hash_.find_neighbours(p, params_.duplicate_check ? params_.check_placement : spatial::DuplicateCheck::Off,
                            ctx.block_size, lists_,
                           [&](std::uint32_t i, const std::uint32_t* nb, const Real* r2, std::size_t count) {
                             // The particle itself (r = 0), then its neighbours (all r < h).
                             Real sum = laws.density.term(m[i], laws.gap2(Real(0)));
                             for (std::size_t k = 0; k < count; ++k)
                               sum += laws.density.term(m[nb[k]], laws.gap2(r2[k]));
                             rho[i] = laws.density.density(sum);
                             pressure[i] = laws.eos.pressure(rho[i]);
                           });
    }
    {
      PhaseScope phase(ctx, "forces.sph");
      add_pair_forces(p, ctx.block_size);
    }
    mean_neighbours_ = lists_.rows() ? static_cast<double>(lists_.interactions()) / static_cast<double>(lists_.rows()) : 0.0;
  }

  // Times a sub-phase when the caller keeps timers.
  struct PhaseScope {
    PhaseScope(const SolverContext<Real>& ctx, std::string_view name) {
      if (ctx.timers) scope.emplace(*ctx.timers, name);
    }
    std::optional<ScopedPhase> scope;
  };

  void add_pair_forces(ParticleSet<Real>& p, std::size_t block_size) {
    // The laws of sph/laws.hpp, as the grid passes use them; V_j = m_j / ρ_j
    // and p_j V_j are formed per pair here (the lists hold no per-particle scratch).
    const SphLaws<Real> laws(params_);
    const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
    const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
    const Real *m = p.mass.data(), *rho = p.density.data(), *pr = p.pressure.data();
    Real *ax = p.acceleration.x.data(), *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
    const auto& L = lists_;
    parallel::for_blocks("sph_forces", L.rows(), block_size, [&](std::size_t first, std::size_t last, std::size_t) {
      for (std::size_t row = first; row < last; ++row) {
        const std::uint32_t i = L.row_particle[row];
        Real px = 0, py = 0, pz = 0, qx = 0, qy = 0, qz = 0;  // pressure and viscosity sums
        Real m6[6] = {};  // the gradient correction's sums (sph/laws.hpp), when it is on
        for (std::size_t k = L.offsets[row]; k < L.offsets[row + 1]; ++k) {
          const std::uint32_t j = L.neighbour[k];
          // 1/r = 0 at r = 0 (coincident particles): no pressure force without a direction.
          const Real r = std::sqrt(L.r2[k]), inv_r = r > Real(0) ? Real(1) / r : Real(0), q = laws.gap(r);
          const Real vol_j = m[j] / rho[j];
          const Real fp = laws.pressure.term(pr[i], vol_j, pr[j] * vol_j, q, inv_r);  // along r⃗ = x_i − x_j
          const Real fv = laws.viscosity.term(vol_j, q);
          const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
          px += fp * dx;
          py += fp * dy;
          pz += fp * dz;
          qx += fv * (vx[j] - vx[i]);
          qy += fv * (vy[j] - vy[i]);
          qz += fv * (vz[j] - vz[i]);
          if (laws.corrected) add_correction_term(laws.correction.term(vol_j, q, inv_r), dx, dy, dz, m6);
        }
        if (laws.corrected) {
          Real correction[6];
          laws.correction.inverse(m6, correction);
          GradientCorrection<Real>::apply(correction, px, py, pz);
        }
        const Real inv_rho = Real(1) / rho[i];
        ax[i] += laws.acceleration(px, qx, inv_rho);
        ay[i] += laws.acceleration(py, qy, inv_rho);
        az[i] += laws.acceleration(pz, qz, inv_rho);
      }
    });
  }

  SphParameters params_;
  StepConditions conditions_;
  spatial::SpatialHash<Real> hash_;
  spatial::NeighbourList<Real> lists_;
  spatial::SortedCellGrid<Real> grid_;
  GridScratch<Real> scratch_;
  std::optional<DfsphKernel<Real>> kernel_;  // DFSPH: built at the first evaluation
  AlignedVector<Real> alpha_;                // DFSPH: α_i of the last evaluation
  DfsphPairs<Real> pairs_;                   // DFSPH: its pairs {j, g(r), r⃗}, for the solves' passes
  AlignedVector<Real> boundary_pressure_;    // thesis's solver: p_b of the last evaluation (scratch)
  std::vector<std::uint64_t> halo_keys_;     // on ranks: the keys of the own particles and their ghosts (scratch)
  const dist::RankOrder<Real>* ranks_ = nullptr;  // the last evaluation's rank order (null: one rank)
  // DFSPH on ranks: the last evaluation's ghosts, the local set (own particles
  // among them, in global order), the own range in it, κ/ρ's field there and
  // a pass's output for every local particle.
  dist::Halo halo_;
  ParticleSet<Real> local_;
  IndexRange own_{};
  std::size_t kr_field_ = 0;
  AlignedVector<Real> local_out_;
  static constexpr std::string_view kLocalKappaField = "dfsph_k_over_rho";
  std::size_t normal_field_ = 0;  // Akinci's normals n_i in local_ (surface tension or adhesion on)
  static constexpr std::string_view kLocalNormalField = "dfsph_surface_normal";
  std::array<AlignedVector<Real>, 3> normals_;  // one rank: the normals n_i; XSPH's Δv (scratch)
  double alpha_cap_ = 0;                     // DFSPH: α's cap (set at the first evaluation with fluid)
  static constexpr double kAlphaCapFactor = 2;
  KernelPath kernel_path() const { return params_.simd ? KernelPath::Simd : KernelPath::Scalar; }

  double mean_neighbours_ = 0;
  std::vector<std::uint64_t> rank_costs_;  // on ranks: the own particles' costs (add_rank_costs)
  double neighbour_sum_ = 0;     // Σ of mean_neighbours_ over evaluations (the summary's mean)
  double halo_ghost_sum_ = 0, halo_owned_sum_ = 0;  // on ranks: Σ ghosts and Σ own particles over evaluations
  std::uint64_t evaluations_ = 0;
  bool used_grid_ = false;
  bool boundary_volumes_ = false;  // ψ_b computed into the boundary particles' masses (state)
  bool moving_boundaries_ = false;  // ψ_b recomputed at every evaluation (set_moving_boundaries)
  bool record_reactions_ = false;  // DFSPH: record_density_reaction() after each density solve
  std::vector<Reaction> reactions_;  // DFSPH: its result, by id (scratch: a step recomputes it)
  // On ranks, with boundary particles: the last evaluation's halo (not
  // inserted) and, while boundary forces are summed, the set with its ghosts.
  dist::Halo reaction_halo_;
  ParticleSet<Real> ghost_set_;
  std::vector<std::uint64_t> ghost_keys_;
  std::size_t fluid_count_ = 0;    // fluid particles at the last evaluation (of all ranks)
  std::uint64_t fluid_count_for_ = std::numeric_limits<std::uint64_t>::max();  // the ranks' particle count it was summed at
};

// Compiled once, in src/sph/sph_fluid.cpp: users link the float and double copies
// instead of compiling them again.
extern template class SphFluid<float>;
extern template class SphFluid<double>;

}  // namespace swirl::sph
