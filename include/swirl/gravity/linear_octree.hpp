// LinearOctree<Real>: the octree swirl's fast gravity stands on, built from
// sorted space-filling-curve keys instead of particle-by-particle insertion.
//
// Build (every pass parallel over fixed blocks, so the tree is the same for
// any thread count):
//   1. the bounding cube of the particles; each particle gets a 63-bit Morton
//      key (21 bits per axis, x lowest: the paper tree's octant numbering);
//   2. the keys are sorted with parallel::RadixSort (stable: ties by index);
//      positions and masses are gathered into curve order (the tree's own SoA
//      copies: order()[s] is the ParticleSet index of sorted slot s);
//   3. nodes are made level by level from key prefixes: a node is a range
//      [begin, end) of sorted slots sharing its prefix; a node with more than
//      bucket_size particles is cut at the 3-bit digit of the next level
//      (binary searches in the sorted keys) into its non-empty octants, which
//      are stored next to each other (children contiguous). The finest level
//      (21) is never split: coincident particles share one leaf;
//   4. multipoles bottom-up, deepest level first, in double: mass, centre of
//      mass and the traceless quadrupole Q_ij = Σ m (3 r_i r_j − r² δ_ij)
//      about the centre of mass (r relative to it), children shifted to the
//      parent's centre by the parallel-axis theorem.
//
// Layout: structure of arrays, one entry per node, nodes in breadth-first
// order (level by level), so a node's children are first_child ..
// first_child + child_count − 1. The walk reads only com_*, mass, q*, open2,
// begin/end and the child range: the layout the group walk and SIMD kernels
// of the next step need.
//
// Opening (a node is used as its expansion iff d² > open2 and the particle is
// not inside it; d = |centre of mass − particle|, l = node side):
//   paper   open2 = (l/λ)²: the paper's l/d < λ. Fails when the centre of
//           mass sits near a corner of the node and λ is large: a particle
//           just outside the opposite face is "far" from the centre of mass
//           yet close to the node's mass there, which the expansion moves
//           away — the error is unbounded (linear_tree_test.cpp,
//           PaperRuleFailsOnAClumpAtACellCorner...: 68 % at λ = 0.9).
//   barnes  open2 = (l/θ + δ)², δ = |centre of mass − geometric centre|
//           (Barnes 1994). An accepted node then has d − δ ≥ l/θ: the
//           particle is at least l/θ from the cube's centre whatever the mass
//           distribution, so it is never inside or next to the cube. Prevents
//           the failure above; for a centred mass (δ = 0) it is the paper's rule.
// Both: the node holding the particle itself is always opened (its own mass
// must never enter an expansion: a self-interaction, and d can be ~0); θ or
// λ = 0 opens everything, and the walk is then the direct sum's very terms.
//
// Walks (LinearTreeSettings::walk):
//   particle  one non-recursive walk per particle with the rule above: the
//             slow twin and reference;
//   group     one walk per group: a node with at most group_size particles
//             whose parent has more (or a larger leaf, which is never cut),
//             groups in curve order. A node is accepted iff it holds no group
//             particle and d_box² > open2, d_box = the distance from its centre
//             of mass to the group's bounding box: d_box ≤ d for every particle
//             of the group, so the test is at least as strict as the
//             per-particle one (and in floating point too: the box distance is
//             computed with the same operations on the nearest coordinate).
//             The walk fills the group's interaction list — cell sources (com,
//             mass, quadrupole) and particle sources (the particles of opened
//             leaves, the group's own first, its self pairs skipped) — which
//             interaction_kernels.hpp evaluates for all the group's particles.
//             Groups go to threads dynamically, costliest first by the last
//             evaluation's interaction counts (kept per sorted slot, so they
//             carry over a rebuild as an estimate); each group's result
//             depends only on the tree, never on the thread or the order.
//
// Active sets (core/active_set.hpp, block time steps): only the active
// particles are computed. The particle walk skips the others (each active
// particle's result is the full evaluation's, bit for bit). The group walk
// skips groups without an active particle; in a partly active group the box
// of the opening test is the active particles' (tighter: fewer nodes opened)
// and only they are targets, the group's own sources listed actives first:
// the same terms as the full evaluation, summed in another order and
// possibly with fewer nodes opened, so equal to it within the opening
// criterion's error and round-off, not bitwise. A fully active group is
// computed exactly as in the full evaluation.
//
// Assembled trees: assemble() adopts nodes and particles made elsewhere — a
// rank's locally essential tree (essential_tree.hpp) — and evaluate() runs the
// group walk above over them, unchanged, for the groups it is given.
//
// Units: G = 1; lengths as the positions; side of the root cube = root_side().
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "swirl/core/active_set.hpp"
#include "swirl/core/aligned.hpp"
#include "swirl/core/morton.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/pair_law.hpp"
#include "swirl/gravity/settings.hpp"
#include "swirl/parallel/radix_sort.hpp"

namespace swirl::gravity {

struct LinearTreeSettings {
  Multipole multipole = Multipole::Quadrupole;
  Criterion criterion = Criterion::Barnes;
  double opening = 0.5;    // λ (paper) or θ (barnes), in [0, 1]
  double softening = 0.01;  // ε
  std::size_t bucket_size = 16;
  Walk walk = Walk::Group;
  std::size_t group_size = 256;  // the group walk's particles per group, at most (unless a leaf holds more)
  bool simd_kernels = true;     // group walk: false uses the kernels' scalar path (the reference)
};

// The key cube of build(): the low corner of the particles' bounding box and
// its largest extent as side (1 when there are no particles or all coincide).
struct KeyCube {
  std::array<double, 3> corner{};
  double side = 1;
};

// The key cube of `count` particles whose coordinates lie in [lo, hi] per
// axis, exactly as build() makes it (so a cube from a global min/max over ranks
// is the one-rank cube). Throws std::invalid_argument for a non-finite extent.
KeyCube key_cube(const std::array<double, 3>& lo, const std::array<double, 3>& hi, std::size_t count);

// The 63-bit Morton key of a position in a key cube, with the operations of
// build(): 21 bits per axis, floor((x − corner)·2^21/side) clamped to the cube
// (the far faces in the last cell). scale = key_scale(cube.side).
inline double key_scale(double side) { return double(std::uint64_t(1) << 21) / side; }
inline std::uint64_t octree_key(double x, double y, double z, const std::array<double, 3>& corner, double scale) {
  constexpr double cells = double(std::uint64_t(1) << 21);
  const double v[3] = {x, y, z};
  std::uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const double c = std::floor((v[a] - corner[std::size_t(a)]) * scale);
    const std::uint64_t q = c >= cells ? std::uint64_t(cells - 1) : (c > 0 ? std::uint64_t(c) : 0);
    key |= morton_spread(q) << a;
  }
  return key;
}

// The node arrays (SoA). Index n in every array is node n; node 0 is the root.
template <class Real>
struct LinearNodes {
  AlignedVector<Real> com_x, com_y, com_z, mass;  // centre of mass, total mass
  AlignedVector<Real> qxx, qxy, qxz, qyy, qyz;    // traceless quadrupole (qzz = −qxx − qyy)
  AlignedVector<Real> open2;                      // squared opening radius (see the header)
  std::vector<std::uint32_t> begin, end;          // sorted particle slots [begin, end)
  std::vector<std::uint32_t> first_child;         // children: first_child .. + child_count − 1
  std::vector<std::uint8_t> child_count;          // 0: a leaf
  std::vector<std::uint8_t> level;                // root 0; side = root side · 2^−level
  std::vector<std::uint64_t> prefix;              // the key prefix (key >> 3·(21 − level))

  std::size_t size() const { return begin.size(); }
};

// What a walk did, summed over the particles walked (interactions: one source
// on one particle, whichever walk; nodes: per walk, so per group for the group walk).
struct WalkCounts {
  std::uint64_t nodes = 0;         // nodes popped from the visit stack
  std::uint64_t multipoles = 0;    // node expansions evaluated
  std::uint64_t pairs = 0;         // particle–particle terms evaluated
};

template <class Real>
class LinearOctree {
 public:
  static constexpr int kLevels = 21;  // 3 × 21 = 63 key bits
  static constexpr std::uint32_t npos = std::numeric_limits<std::uint32_t>::max();

  // Builds the tree of all particles of p with its own keys and sort (the
  // particles stay where they are; order() maps sorted slots to them).
  // block_size: the parallel block of the per-particle passes (the result
  // does not depend on it).
  void build(const ParticleSet<Real>& p, const LinearTreeSettings& settings, std::size_t block_size);

  // Builds the tree as a view of particles already sorted by 63-bit Morton
  // keys (the simulation's order, spatial/particle_order.hpp): sorted_keys[i]
  // is particle i's key in the cube of side `side` at `corner` (21 bits per
  // axis). Nothing is sorted or copied: the walk reads p's arrays, which must
  // outlive the tree's use; order() is the identity.
  void build_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                    const std::array<double, 3>& corner, double side, const LinearTreeSettings& settings,
                    std::size_t block_size);

  // Adopts a tree assembled elsewhere (a rank's locally essential tree,
  // essential_tree.hpp) for the group walk: nodes as nodes() describes them
  // (children contiguous, in child order; [begin, end) ranges of the particles
  // given here, nesting like the tree's; moments and open2 as build() stores
  // them), the particles in slot order (copied), and the groups to evaluate
  // (node indices, each node's particles all given). evaluate() then walks
  // these groups only, over these nodes, with the group walk unchanged, and
  // writes the field of their particles (indexed by slot; the other slots'
  // entries are left as they were). Needs walk = group; an active set given
  // to evaluate() is indexed by slot (the particles given here).
  void assemble(LinearNodes<Real> nodes, std::span<const Real> x, std::span<const Real> y, std::span<const Real> z,
                std::span<const Real> m, std::vector<std::uint32_t> groups, const LinearTreeSettings& settings);

  // Declares that the caller permuted its ParticleSet by order() (p.reorder):
  // ParticleSet index and sorted slot now coincide, order() becomes the identity.
  void adopt_curve_order();

  // Writes out[order()[s]] for every particle (out resized to the particle
  // count), with settings().walk; with an active set (indexed like the
  // ParticleSet), for its particles only. Not const: the group walk keeps its
  // per-thread lists and the groups' costs for the next call.
  WalkCounts evaluate(GravityField<Real>& out, std::size_t block_size, const ActiveSet& active = {});

  // After a full group walk: adds to out[order()[s]] (out: one entry per
  // particle) the length of the interaction list particle s was evaluated
  // with — its group's particle and cell sources, itself excluded. An integer
  // measure of the walk's work per particle, for balancing ranks
  // (dist/rank_order.hpp): the same for every run, unlike a timing.
  void add_walk_costs(std::span<std::uint64_t> out) const;

  // The group walk's groups (node indices, in curve order), and the order the
  // last group walk handed them to the threads (indices into groups()).
  std::span<const std::uint32_t> groups() const { return groups_; }
  std::span<const std::uint32_t> group_schedule() const { return schedule_; }

  const LinearNodes<Real>& nodes() const { return nodes_; }
  std::span<const std::uint32_t> order() const { return order_; }
  std::span<const std::uint64_t> keys() const { return keys_; }
  // Particles in curve order.
  std::span<const Real> x() const { return x_; }
  std::span<const Real> y() const { return y_; }
  std::span<const Real> z() const { return z_; }
  std::span<const Real> m() const { return m_; }
  // The root cube: lower corner and side.
  std::array<double, 3> root_corner() const { return corner_; }
  double root_side() const { return side_; }
  int depth() const { return depth_; }
  std::size_t leaf_count() const;
  // Bytes held by the tree (nodes, sorted copies, keys, sort buffers).
  std::size_t bytes() const;
  const LinearTreeSettings& settings() const { return settings_; }

 private:
  void check(const ParticleSet<Real>& p, const LinearTreeSettings& settings, std::size_t block_size) const;
  void make_keys(const ParticleSet<Real>& p, std::size_t block_size);
  void make_nodes();
  void make_multipoles();
  void walk_one(std::size_t s, Accumulator<Real>& acc, WalkCounts& counts) const;

  // One thread's interaction list and the group's field (reused across groups).
  struct GroupLists {
    AlignedVector<Real> px, py, pz, pm;                                   // particle sources
    AlignedVector<Real> cx, cy, cz, cm, cqxx, cqxy, cqxz, cqyy, cqyz;      // cell sources
    AlignedVector<Real> ax, ay, az, phi;                                  // the group's field
    AlignedVector<Real> tx, ty, tz;                                       // a partly active group's targets
    std::vector<std::uint32_t> targets;                                   // the targets' sorted slots
    std::vector<std::uint32_t> stack;
  };
  void make_groups();
  WalkCounts evaluate_particles(GravityField<Real>& out, std::size_t block_size) const;
  WalkCounts evaluate_groups(GravityField<Real>& out);
  // Fills lists for group g (its active particles' list when active_slot_ is
  // set: lists.targets); returns the nodes popped.
  std::uint64_t walk_group(std::size_t g, GroupLists& lists) const;

  LinearTreeSettings settings_;
  LinearNodes<Real> nodes_;
  parallel::RadixSort<std::uint64_t> sorter_;
  AlignedVector<std::uint64_t> raw_keys_;
  std::span<const std::uint64_t> keys_;  // sorted: sorter_'s, or the caller's (build_sorted)
  std::vector<std::uint32_t> order_;
  std::span<const Real> x_, y_, z_, m_;  // particles in curve order: own_*, or the caller's
  AlignedVector<Real> own_x_, own_y_, own_z_, own_m_;  // build(): the sorted copies
  std::array<double, 3> corner_{};
  double side_ = 0;
  int depth_ = 0;
  std::size_t block_size_ = 1024;
  std::vector<std::uint32_t> groups_;    // group walk: the group nodes
  std::vector<std::uint32_t> schedule_;  // the last walk's order of groups
  std::vector<double> slot_cost_;        // per sorted slot: its group's last cost / its size
  std::vector<WalkCounts> group_counts_;
  std::vector<GroupLists> lists_;        // per thread
  std::vector<std::uint8_t> active_slot_;  // this evaluation's active flags per sorted slot (empty: all)
  bool assembled_ = false;                 // assemble(): the groups are given, not made
};

extern template class LinearOctree<float>;
extern template class LinearOctree<double>;

}  // namespace swirl::gravity
