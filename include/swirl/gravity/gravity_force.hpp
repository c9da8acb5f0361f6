// GravityForce<Real>: self-gravity as a solver (force/solver.hpp).
//
// Each evaluation computes the field of the particles (direct sum,
// Barnes–Hut with the configured scheme, or the fast multipole method), adds G·a_i to particles.acceleration
// and writes G·φ_i into the field "potential", so W = ½ Σ m_i φ_i comes from
// the same walk as the force. The tree codes work in G = 1; G scales the result
// (1 in N-body units, 6.674e-11 m³ kg⁻¹ s⁻² in SI: scene key simulation.units).
// With ctx.timers the time is recorded as "forces.tree_build" and "forces.walk".
//
// The default (global scheme, linear tree, settings.reorder), and the FMM with
// settings.reorder, ask for the simulation's particle order and build the
// linear octree as a view of it
// (gravity/linear_octree.hpp: its nodes are prefixes of the order's sorted
// Morton keys); it never moves a particle. Every other choice — the paper's
// tree and schemes, reorder = false, an evaluation without an order — builds
// its own structure over the particles where they are.
//
// Time-step condition (ε the Plummer softening):
//   ε > 0   Δt ≤ η · sqrt(ε / |a|max)
//   ε = 0   Δt ≤ η · sqrt(d / |a|max), d = L / N^(1/3) the mean particle
//           separation (L the largest extent of the particles' bounding box):
//           without softening the smallest length the forces resolve is the
//           spacing of the particles themselves.
//
// With an active set in the context (block time steps) only the active
// particles' acceleration and potential are computed and written (the linear
// tree, the direct sum and the FMM skip the others — the FMM keeps the
// interactions of cells holding an active particle; the paper's schemes
// compute all).
// The metric particle_force_evaluations counts the particles computed over
// the run: the cost measure block steps are judged by.
//
// Results are bit-identical for any thread count.
// On several ranks (SolverContext::ranks) the linear octree's group walk
// runs as the locally essential tree (essential_tree.hpp) over the global
// order, whose cuts rank_cuts() puts on group boundaries: every particle's
// field is the one-rank field, bit for bit. The direct sum and the FMM run
// there replicated: every rank gathers the whole set (positions, masses, the
// order's keys) in the one-rank memory order and computes the one-rank field
// of its own particles only, as an active set (the one-rank bits; O(N)
// memory per rank; the FMM's tree and upward pass are every rank's, its
// interactions divide among the ranks). The paper's schemes and the particle
// walk are refused there.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swirl/force/solver.hpp"
#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/essential_tree.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/fmm.hpp"
#include "swirl/gravity/settings.hpp"

namespace swirl::gravity {

// What the solver needs beyond the tree's settings.
struct SelfGravityOptions {
  double G = 1;       // the gravitational constant in the scene's units (> 0)
  double eta = 0.75;  // η of the time-step condition
};

template <class Real>
class GravityForce final : public Solver<Real> {
 public:
  // Validates the settings: std::invalid_argument names a bad parameter.
  explicit GravityForce(const GravitySettings& settings = {}, const SelfGravityOptions& options = {});

  std::string_view name() const override { return "self_gravity"; }
  void declare_fields(ParticleSet<Real>& particles) override;
  spatial::OrderRequest order_request() const override;
  void add_acceleration(ParticleSet<Real>& particles, const SolverContext<Real>& ctx) override;
  // On ranks: cuts on group boundaries of the global tree (group_aligned_cuts).
  std::vector<std::uint64_t> rank_cuts(const dist::Communicator& comm, std::span<const std::uint64_t> keys,
                                       std::vector<std::uint64_t> cuts) const override;
  // On ranks: each particle's interaction-list length in the last walk.
  void add_rank_costs(std::span<std::uint64_t> costs) const override;
  // Empty when these settings run on several ranks (the linear octree's group
  // walk, as a view of the order: the locally essential tree; the direct sum
  // and the FMM, replicated over the whole set gathered on every rank);
  // otherwise what does not.
  std::string distributed_support() const;

  ScanNeeds scan_needs() const override { return {false, !(settings_.softening > 0)}; }
  void add_limits(const StepScan& scan, std::size_t n, std::vector<StepLimit>& out) const override;
  LimitText explain(const StepLimit& limit, std::string_view particle) const override;
  std::string advice() const override { return "for close encounters, a larger softening"; }

  std::vector<std::string> diagnostic_columns() const override { return {"virial_ratio", "mean_nodes_visited"}; }
  void add_diagnostics(const ParticleSet<Real>& particles, const dist::BlockFold& fold,
                       std::vector<double>& row) const override;
  double potential_energy(const ParticleSet<Real>& particles, const dist::BlockFold& fold) const override;
  void add_metrics(NamedValues& out) const override;
  void add_rank_metrics(NamedValues& out) const override;
  std::size_t scratch_bytes() const override;  // the tree, and on ranks the replicated methods' whole set
  void save_state(NamedValues& out) const override;
  void load_state(const NamedValues& values) override;

  const GravitySettings& settings() const { return settings_; }
  const SelfGravityOptions& options() const { return options_; }
  // A new softening ε (finite, ≥ 0) from the next evaluation on (swirl view's
  // slider; call Simulation::parameters_changed() after it, between steps).
  void set_softening(double softening);
  // The last evaluation: nodes visited per particle (N − 1 for the direct sum), trees, times.
  const GravityStats& stats() const { return stats_; }
  // The last evaluation's field, in G = 1 units.
  const GravityField<Real>& field() const { return field_; }

 private:
  bool views_order() const;

  GravitySettings settings_;
  SelfGravityOptions options_;
  BarnesHut<Real> tree_;
  EssentialTree<Real> essential_;  // on several ranks
  bool walked_on_ranks_ = false;     // essential_ has evaluated every particle now held
  // On ranks, summed over builds: the essential tree's imported nodes and
  // particles, and this rank's own particles.
  double imported_nodes_ = 0, imported_particles_ = 0, own_particles_ = 0;
  Fmm<Real> fmm_;
  // On ranks, the replicated methods (direct sum, FMM): the whole set gathered
  // here (positions and masses), its keys, which of its particles are this
  // rank's active ones, and its field; kept between evaluations so that a
  // step does not allocate them again.
  ParticleSet<Real> whole_;
  std::vector<std::uint64_t> whole_keys_;
  std::vector<std::int32_t> whole_active_;
  GravityField<Real> whole_field_;
  GravityField<Real> field_;
  GravityStats stats_;
  double nodes_sum_ = 0;  // Σ mean_nodes_visited over evaluations (the summary's mean)
  std::uint64_t evaluations_ = 0;
  double particle_evaluations_ = 0;  // Σ particles whose field an evaluation computed (all, or the active ones)
  std::size_t particles_ = 0;
};

extern template class GravityForce<float>;
extern template class GravityForce<double>;

}  // namespace swirl::gravity
