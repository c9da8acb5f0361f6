// Octree<Real>: the paper's Barnes–Hut tree (Demiroz et al. 2011, section 2 and Fig. 1).
//
// Build: particles are inserted one by one from the root; every node on the way
// adds the particle's mass and mass moment (Fig. 1, "update centre of mass and
// total mass of each internal node on the way"); a leaf that receives a second
// particle is split until the two separate. Coincident (or nearly so) particles
// would split forever, so the depth is capped at max_depth: a leaf there keeps
// a bucket of any number of particles. After insertion the nodes are renumbered
// depth first, so the sub-tree of node n is the index range [n, end(n)): its
// first child is n + 1, the next sibling of child c is end(c), and "node n holds
// leaf l" is n ≤ l < end(n). Section 4.2's depth-first split relies on this.
//
// Walk: non-recursive, with an explicit visit list (Fig. 1). A popped node is
//   - internal: used as one particle (its mass at its centre of mass) if
//     size / d < λ, d = |centre of mass − x| (section 2), otherwise its children
//     are added to the list. A node holding the particle itself is always
//     opened (our addition: a particle never feels its own mass; it changes
//     nothing for λ ≤ 1/√3, where such a node can never pass the test);
//   - a leaf: each of its particles except the particle itself interacts exactly.
// With λ = 0 no internal node passes, so the walk is the direct sum.
//
// Invariants: every member is in exactly one leaf; a node's mass is the sum of
// its particles' masses; a one-particle leaf holds that particle's exact
// position and mass (so λ = 0 adds the direct sum's very terms).
// Units: G = 1; size is the side of the node's cube, in length units.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/pair_law.hpp"

namespace swirl::gravity {

template <class Real>
class Octree {
 public:
  static constexpr std::uint32_t npos = std::numeric_limits<std::uint32_t>::max();
  // Cells below root side · 2⁻³² (≈ 10⁻¹⁰ of the root) are not split further.
  static constexpr int max_depth = 32;

  struct Node {
    Real x, y, z;         // centre of mass
    Real mass;            // total mass
    Real size;            // side of the node's cube
    std::uint32_t end;    // one past the last node of this sub-tree (depth-first numbering)
    std::uint32_t first;  // leaf: first slot of its particles in the leaf arrays
    std::uint32_t count;  // leaf: number of particles (≥ 1); internal node: 0
  };

  // The particle a walk computes the field for.
  struct Target {
    Real x, y, z;
    std::uint32_t particle = npos;  // its index in the ParticleSet
    std::uint32_t leaf = npos;      // the leaf holding it in this tree, or npos
  };

  // Builds the tree of the particles p[members[0]], p[members[1]], ... inserted in that order.
  void build(const ParticleSet<Real>& p, std::span<const std::uint32_t> members);

  std::span<const Node> nodes() const { return nodes_; }
  // Particle indices in leaf (depth-first) order.
  std::span<const std::uint32_t> leaf_particles() const { return leaf_particle_; }
  // The leaf holding members[slot] of the last build.
  std::uint32_t leaf_of(std::size_t slot) const { return leaf_of_[slot]; }
  // Deepest level reached (root = 0).
  int depth() const { return depth_; }

  // Section 2's test for an internal node n: used as one particle at target
  // (size / d < λ as size² < λ²·d², no division, never true for λ = 0), unless
  // it holds the target (our addition: a particle never feels its own mass).
  bool accepts(std::uint32_t n, const Target& target, Real lambda2) const {
    const Node& node = nodes_[n];
    const Real dx = node.x - target.x, dy = node.y - target.y, dz = node.z - target.z;
    const bool holds_target = target.leaf - n < node.end - n;  // n ≤ leaf < end, unsigned
    return node.size * node.size < lambda2 * (dx * dx + dy * dy + dz * dz) && !holds_target;
  }

  // Adds to acc the field at target of every particle below the nodes `entries`
  // (visited in that order), per the header comment; lambda2 = λ², eps2 = ε².
  // `visit` is scratch. Returns the number of nodes taken from the visit list.
  // One compiled copy for every caller (octree.cpp), so that the same walk
  // rounds the same way whichever scheme calls it (a one-unit subtree walk is
  // the global walk, bit for bit).
  std::uint32_t walk(std::span<const std::uint32_t> entries, const Target& target, Real lambda2, Real eps2,
                     Accumulator<Real>& acc, std::vector<std::uint32_t>& visit) const;

 private:
  // A node while particles are being inserted (geometry and moments in double).
  struct Cell {
    double cx, cy, cz, half;    // cube centre and half side
    double m, mx, my, mz;       // mass and mass moment Σ m·x
    std::array<std::int32_t, 8> child;  // -1: none
    std::uint32_t head, tail;   // leaf: bucket list of member slots (linked by next_)
    std::uint32_t count;        // leaf: particles; internal or empty: 0
    std::int32_t depth;
    bool internal;
  };

  void add_leaf(std::uint32_t parent, std::uint32_t slot);
  void insert(std::uint32_t slot);
  void renumber(const ParticleSet<Real>& p, std::span<const std::uint32_t> members);

  std::vector<Node> nodes_;
  std::vector<std::uint32_t> leaf_particle_;
  AlignedVector<Real> leaf_x_, leaf_y_, leaf_z_, leaf_m_;  // positions and masses in leaf order
  std::vector<std::uint32_t> leaf_of_;
  int depth_ = 0;
  // Build scratch, kept to reuse its capacity.
  std::vector<Cell> cells_;
  std::vector<std::array<double, 4>> slot_;  // x, y, z, m of each member
  std::vector<std::uint32_t> next_;
  std::vector<std::uint32_t> subtree_size_;
};

extern template class Octree<float>;
extern template class Octree<double>;

}  // namespace swirl::gravity
