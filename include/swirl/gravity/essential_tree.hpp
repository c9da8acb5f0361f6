// Gravity across ranks: the locally essential tree (issue 19 item 4;
// docs/design/mpi.md, "Gravity across ranks").
//
// Where it lives: in gravity/, which may include dist/ (dist is below gravity
// in tests/layering/check_layering.py); dist knows nothing of trees. MPI stays
// inside src/dist: everything here goes through dist::Communicator.
//
// The setting. Ranks hold contiguous ranges of the global key order
// (dist::distribute_in_key_order: rank r's particles are the global sorted
// slots [first_r, first_r + n_r), sorted by key), keys in one global key cube
// (global_key_cube: an exact min/max over ranks, the cube LinearOctree::build()
// makes on one rank), and cuts on group boundaries of the global tree
// (group_aligned_cuts). EssentialTree::evaluate() then gives every particle of
// every rank the acceleration and potential that the one-rank LinearOctree
// group walk with the same settings gives it, BIT FOR BIT (tested on 1-4 ranks:
// tests/gravity/essential_tree_mpi_test.cpp).
//
// How (build(), collective):
//   1. The top tree. A node of the global tree "spans" when particles of two or
//      more ranks lie in it; such a node contains a cut key strictly inside its
//      key range, so the candidates are the prefixes of the cut keys (at most
//      21 per cut). Every rank counts its particles in each candidate; one
//      exact all-gather of the counts tells every rank the global count of
//      each, and which span. A spanning node is split (its global count rules
//      it, as on one rank). The "local roots" are the children of spanning
//      nodes that do not span: each lies on one rank, whose particles alone
//      make its whole subtree.
//   2. Each rank builds the subtrees of its local roots from its particles with
//      the one-rank rules (split above bucket_size particles, never at level
//      21; octants in order) and the one-rank arithmetic (the same out-of-line
//      functions compute a leaf's moments, a parent's from its children, the
//      stored node: src/gravity/tree_moments.hpp).
//   3. The local roots (key prefix, global slot range, leaf or not, and their
//      moments in double, unrounded) are all-gathered; every rank then combines
//      the spanning nodes' moments bottom-up from whole children in child order
//      — the one-rank summation, on every rank the same bits.
//   4. Group boxes (each rank's groups: global slot range and the bounding
//      box of their particles) are all-gathered.
//   5. Export. Rank s sends rank r the part of its subtrees that r's group
//      walks can open: it replays, for every group of r, the walk's decisions
//      on the top tree (ancestors of the group are opened; other nodes by the
//      opening test against the group's box) and on its own subtrees, with the
//      test made conservative (computed in double and opened up to a relative
//      1e-4 beyond the walk's radius, so it opens everything the walk opens,
//      whatever the rounding of the walk's Real arithmetic). Nodes reached are
//      sent as expansions (centre of mass, mass, quadrupole, opening radius,
//      global slot range); leaves opened, as their particles.
//   6. Each rank assembles its tree: the top tree, its own subtrees, and what
//      every other rank sent (children contiguous, in child order; particles
//      in global slot order, so every node's range nests as on one rank), and
//      LinearOctree::assemble() runs the group walk over it unchanged for its
//      own groups. Before that, on its first call and every 64th
//      (set_check_every), build() replays its own groups' walks and throws
//      std::logic_error if one would open a node whose children or particles
//      are missing (it never should: the export is a superset).
//
// Where bit-identity could break, and what holds it:
//   - the key frame: a global exact min/max gives the one-rank cube;
//   - the tree's shape: a node's split depends on its global count and level
//     only; counts of spanning nodes are exact integer sums;
//   - a group or leaf across a cut: its walk (box, opening tests, own
//     particles first) would be split between ranks. Cuts on depth boundaries
//     (dist::balanced_cut_keys) are not enough — a group can hold a whole
//     octant or more — so group_aligned_cuts() moves each cut to the nearer
//     end of the group that holds it, and build() refuses cuts that split a
//     group or a leaf (std::invalid_argument);
//   - moments of spanning nodes: from whole children, in child order, their
//     double moments exchanged unrounded, by the one-rank functions;
//   - the walk and its lists: the same code (assemble()) over the same nodes in
//     the same child order, so the same cells and particles in the same order
//     reach the same SIMD kernels.
// Nothing here is only "close": every rank's field is the one-rank field.
//
// Units: as LinearOctree (G = 1).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "swirl/core/active_set.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/linear_octree.hpp"

namespace swirl::gravity {

// The key cube of all ranks' particles: the cube LinearOctree::build() makes
// of the gathered set (an exact min/max over ranks). Collective.
template <class Real>
KeyCube global_key_cube(const dist::Communicator& comm, const ParticleSet<Real>& p);

// keys[i]: particle i's 63-bit key in the cube (LinearOctree::build()'s keys).
template <class Real>
void octree_keys(const ParticleSet<Real>& p, const KeyCube& cube, std::vector<std::uint64_t>& keys);

// The cut keys moved onto group boundaries of the global tree of these
// settings (bucket_size, group_size): a cut strictly inside a group's key range
// goes to the nearer end of that group by particle count (ties: the lower). A
// group is a leaf or holds at most group_size particles (LinearOctree's group
// walk); afterwards no group and no leaf has particles on two ranks. keys: this
// rank's keys, any order; cut_keys nondecreasing (size − 1 of them).
// Collective: one exact integer all-reduce.
std::vector<std::uint64_t> group_aligned_cuts(const dist::Communicator& comm, std::span<const std::uint64_t> keys,
                                              std::span<const std::uint64_t> cut_keys,
                                              const LinearTreeSettings& settings);

// What one build() exchanged and assembled (this rank's figures).
struct EssentialTreeStats {
  std::uint64_t spanning_nodes = 0;  // the top tree: nodes with particles on two or more ranks
  std::uint64_t local_roots = 0;     // all ranks' (every rank holds their expansions)
  std::uint64_t groups = 0;          // this rank's groups
  // The locally essential tree proper (all-to-all), to and from the other ranks.
  std::uint64_t nodes_sent = 0, particles_sent = 0, bytes_sent = 0;
  std::uint64_t nodes_received = 0, particles_received = 0, bytes_received = 0;
  // Of those received, what this rank's walks visit (nodes) and open
  // (leaves' particles): counted on checked builds only (0 otherwise).
  bool checked = false;
  std::uint64_t nodes_used = 0, particles_used = 0;
  // All-gathers (spanning counts, local roots, group boxes): bytes this rank received.
  std::uint64_t bytes_gathered = 0;
  // The assembled tree.
  std::uint64_t tree_nodes = 0, tree_particles = 0;
};

template <class Real>
class EssentialTree {
 public:
  // Collective. p: this rank's particles, its range of the global key order
  // (sorted by key; global slots first_global_index ..); keys: theirs, in the
  // cube; cut_keys: the size − 1 cuts the particles were distributed with, on
  // group boundaries (group_aligned_cuts). settings.walk must be group.
  // active: the particles of p (in p's order) whose field the next
  // evaluate() must give (block time steps, core/active_set.hpp); a partly
  // active set exchanges and walks only the groups holding active particles,
  // with the box of their active particles, as LinearOctree's walk does on one
  // rank. Keeps no reference to p; keeps a copy of active's flags.
  void build(const dist::Communicator& comm, const ParticleSet<Real>& p, std::span<const std::uint64_t> keys,
             std::uint64_t first_global_index, std::span<const std::uint64_t> cut_keys, const KeyCube& cube,
             const LinearTreeSettings& settings, std::size_t block_size, const ActiveSet& active = {});

  // The field of this rank's particles (out resized to their count, in p's
  // order): the one-rank group walk's bits, for the active particles of the
  // last build() (the others' entries are unspecified). Not collective.
  WalkCounts evaluate(GravityField<Real>& out);
  // After evaluate() of a build with every particle active: adds to out (one
  // entry per own particle, in p's order) each one's interaction-list length
  // (LinearOctree::add_walk_costs).
  void add_walk_costs(std::span<std::uint64_t> out) const;

  const EssentialTreeStats& stats() const { return stats_; }
  // build() checks the import on its first call and then on every k-th
  // (0: never): it replays this rank's group walks over the assembled tree
  // and throws std::logic_error if one would open a node another rank did
  // not send. The export is a superset by construction (its test is the
  // walk's, in double, with a margin), so the check guards against a logic
  // error, not rounding; run on every build, it costs about twice the rest
  // of build() (docs/performance/ranks.md).
  void set_check_every(std::uint64_t k) { check_every_ = k; }
  // The assembled tree (nodes and particles in this rank's layout).
  const LinearOctree<Real>& tree() const { return tree_; }

 private:
  LinearOctree<Real> tree_;
  GravityField<Real> field_;
  std::vector<std::int32_t> slot_active_;  // per slot of the assembled tree: 1 active; empty: all
  std::size_t own_offset_ = 0, own_count_ = 0, block_size_ = 1024;
  EssentialTreeStats stats_;
  std::uint64_t check_every_ = 64, builds_ = 0;
};

extern template KeyCube global_key_cube<float>(const dist::Communicator&, const ParticleSet<float>&);
extern template KeyCube global_key_cube<double>(const dist::Communicator&, const ParticleSet<double>&);
extern template void octree_keys<float>(const ParticleSet<float>&, const KeyCube&, std::vector<std::uint64_t>&);
extern template void octree_keys<double>(const ParticleSet<double>&, const KeyCube&, std::vector<std::uint64_t>&);
extern template class EssentialTree<float>;
extern template class EssentialTree<double>;

}  // namespace swirl::gravity
