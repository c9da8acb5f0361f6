// BarnesHut<Real>: the paper's tree code with its parallel schemes (Demiroz et
// al. 2011, sections 2 and 4), computing a GravityField for a ParticleSet.
//
// Which trees a particle walks (the approximation) is the paper's:
//   global     one tree of all particles, walked from the root: the linear
//              octree (linear_octree.hpp, the default: settings.tree) or the
//              paper's insertion-built tree.
//   subdomain  (4.1) particles sorted in Morton order of their positions in the
//              bounding cube, cut into sub-domains of ≤ subdomain_size
//              particles; one local tree per sub-domain; every particle walks
//              every local tree and its force is their sum. The cut
//              (settings.subdomain_split): `adaptive` (ours) packs Morton cells
//              greedily, splitting from the root any cell over the size;
//              `paper` packs the paper's fixed 8³ = 512 cells the same way and
//              cuts a cell over the size into equal runs (the paper does not
//              say what it did with one).
//   subtree    (4.2) one global tree, cut depth first into units, a unit being
//              whole sub-trees packed in depth-first order; every particle
//              walks every unit, its force is the sum over units. Unit size
//              (settings.subtree_split): ≤ subtree_nodes nodes (ours) or the
//              paper's node total / subtree_parts. A node with more nodes below
//              it than a unit holds straddles units; settings.upper_nodes: such
//              a node is always opened, never a cluster (ours: every mass is
//              then counted once by construction), or, as the paper's
//              replicated upper levels, walked by every unit below it and used
//              as a cluster where the λ rule allows, that cluster counting for
//              the unit holding the node's first descendant only (the others
//              skip it: the paper does not say how it avoided counting it
//              several times; with this rule the sum over units is the global
//              walk's field).
// Sub-domains and units depend on the particles and the settings only, never
// on the thread count.
//
// Who computes what: as on the Cell, a thread walks whole trees (units) for all
// particles, the trees dealt heaviest first to the least loaded thread. The
// weights: a sub-domain's nodes explored in the previous evaluation (4.1.1),
// found by what the sub-domain is (its Morton cells) rather than by its index;
// a sub-domain new this evaluation is weighed by its particles times the last
// evaluation's nodes per particle, and the first evaluation by particle counts;
// units by their node count (4.2.1). global hands particle blocks to threads
// dynamically. Determinism: each tree's contribution is summed per particle in
// tree order, whatever thread computed it, so results are bit-identical for
// any thread count (and the balance changes only who computes what).
//
// Units: G = 1; the softening and λ come from GravitySettings.
#pragma once

#include <array>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/linear_octree.hpp"
#include "swirl/gravity/octree.hpp"
#include "swirl/gravity/settings.hpp"

namespace swirl::gravity {

// What the last evaluation did.
struct GravityStats {
  double mean_nodes_visited = 0;  // nodes taken from visit lists per particle walked, over all trees it walked
  std::size_t walked = 0;         // particles whose field was computed (the active ones, or all)
  std::size_t trees = 0;          // sub-domain trees, sub-tree units, or 1 (global); 0 for the direct sum
  std::size_t nodes = 0;          // nodes built (sum over trees)
  int depth = 0;                  // deepest tree level
  double tree_build_seconds = 0;  // sorting, tree construction, cutting into units
  double force_seconds = 0;       // walks and the per-particle sums
  // Linear tree only (0 otherwise):
  double mean_interactions = 0;   // node expansions + particle pairs evaluated per particle
  std::size_t tree_bytes = 0;     // memory the tree holds (nodes, sorted copies, keys, sort buffers)
  std::size_t leaves = 0;
};

template <class Real>
class BarnesHut {
 public:
  // Validates the settings (std::invalid_argument); settings.method is ignored.
  explicit BarnesHut(const GravitySettings& settings);

  // Overwrites out (resized to p.size()) with the tree field of p. block_size
  // is the block of the per-particle passes (results do not depend on it).
  // With an active set the linear tree computes only its particles
  // (linear_octree.hpp); the paper's tree and schemes compute every particle.
  void compute(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
               const ActiveSet& active = {});
  // The linear tree as a view of particles already sorted along the Morton
  // curve (the simulation's order: sorted_keys[i] is particle i's 63-bit key
  // in the cube of side `side` at `corner`): no sort, no copy. Linear tree only.
  void compute_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                      const std::array<double, 3>& corner, double side, GravityField<Real>& out,
                      std::size_t block_size, const ActiveSet& active = {});

  // The linear octree's settings from these (multipole, opening, buckets, walk, ...).
  LinearTreeSettings linear_settings() const;
  // True when compute() walks the linear octree (scheme global, tree linear).
  bool uses_linear_tree() const { return settings_.scheme == Scheme::Global && settings_.tree == Tree::Linear; }
  // The linear octree of the last evaluation (empty unless uses_linear_tree()).
  const LinearOctree<Real>& linear_tree() const { return linear_; }

  const GravitySettings& settings() const { return settings_; }
  const GravityStats& stats() const { return stats_; }
  // Nodes explored by all particles in each tree (unit) in the last
  // evaluation: the load metric of section 4.1.1.
  std::span<const std::uint64_t> work() const { return work_; }
  // The weights the last evaluation dealt its trees (units) by, in tree order.
  std::span<const std::uint64_t> balance_weights() const { return weights_; }
  // Subdomain scheme: each sub-domain's [begin, end) in the Morton order of
  // the last evaluation (so end − begin particles); empty for other schemes.
  std::span<const std::pair<std::size_t, std::size_t>> subdomains() const { return runs_; }

  // Memory for the per-tree fields of the subdomain and subtree schemes
  // (N × 4 reals per tree in flight; default 64 MiB): the trees are walked
  // and balanced in batches of as many as it holds, at least one per thread.
  // Results do not depend on it.
  void set_tree_buffer_bytes(std::size_t bytes) { buffer_bytes_ = bytes; }

 private:
  // A tree to walk, and the nodes its walk starts from.
  struct Source {
    std::uint32_t tree;
    std::uint32_t entries_begin, entries_end;  // into entries_
  };
  // What a sub-domain is, whatever its index: the Morton key range of its
  // cells, and which of `parts` equal runs of one cell it is (part 0 of 1 for
  // whole cells).
  struct SubdomainId {
    std::uint64_t key_begin, key_end;
    std::uint32_t part, parts;
    auto operator<=>(const SubdomainId&) const = default;
  };
  class RunPacker;

  void compute_impl(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                    const ActiveSet& active);
  void compute_linear(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                      const ActiveSet& active);
  void evaluate_linear(std::size_t n, GravityField<Real>& out, std::size_t block_size, double build_seconds,
                       const ActiveSet& active);
  void build_subdomains(const ParticleSet<Real>& p);
  void split_adaptive();
  void split_paper_cells();
  void subdomain_weights();
  void build_global_tree(const ParticleSet<Real>& p);
  void cut_units();
  void unit_weights();
  void walk_global(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size);
  void walk_sources(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                    const std::vector<std::uint64_t>& weights);
  std::uint64_t walk_source(const ParticleSet<Real>& p, std::size_t s, GravityField<Real>& into) const;
  std::uint64_t walk_upper(std::uint32_t unit, const typename Octree<Real>::Target& target, Real lambda2, Real eps2,
                           Accumulator<Real>& acc, std::vector<std::uint32_t>& visit,
                           std::vector<std::uint32_t>& entries) const;

  GravitySettings settings_;
  GravityStats stats_;
  std::vector<Octree<Real>> trees_;
  std::vector<Source> sources_;
  std::vector<std::uint32_t> entries_;
  std::vector<std::pair<std::size_t, std::size_t>> runs_;  // sub-domains: [begin, end) of order_
  std::vector<SubdomainId> ids_;                              // each run's identity
  // The last evaluation's sub-domains by identity (sorted) with their work, and its work per particle.
  std::vector<std::pair<SubdomainId, std::uint64_t>> measured_;
  double measured_work_per_particle_ = 0;
  // Subtree units: the first and last unit below each node (a straddling node
  // spans several; a unit's entry spans its own), and the unit size.
  std::vector<std::uint32_t> unit_first_, unit_last_;
  std::size_t unit_nodes_ = 0;
  std::vector<std::uint32_t> order_;  // particles in walk order (Morton or leaf order)
  std::vector<std::uint32_t> home_tree_, home_leaf_;  // the tree and leaf holding each particle
  std::vector<std::uint64_t> work_, weights_;
  std::vector<GravityField<Real>> buffers_;  // one tree's contribution per buffer
  std::size_t buffer_bytes_ = std::size_t(64) << 20;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys_;
  std::vector<std::uint32_t> identity_;
  LinearOctree<Real> linear_;
};

extern template class BarnesHut<float>;
extern template class BarnesHut<double>;

}  // namespace swirl::gravity
