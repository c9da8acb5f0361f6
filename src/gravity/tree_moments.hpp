// The linear octree's per-node arithmetic, private to src/gravity: the
// moments of a leaf from its particles, of an internal node from its
// children, and the stored node (moments rounded to Real, the opening radius).
// LinearOctree (linear_octree.cpp) and the locally essential tree
// (essential_tree.cpp) both call these very functions, which are defined once
// (linear_octree.cpp) and never inlined: a node's bits are then the same
// whichever of them computes it, whatever the compiler would contract or
// reorder in another context (FMA contraction stays on in swirl's build).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "swirl/gravity/linear_octree.hpp"

namespace swirl::gravity::detail {

// A node's moments while they are summed (double): mass, centre of mass and
// the traceless quadrupole about it (qzz = −xx − yy).
struct NodeMoments {
  double m, x, y, z, xx, xy, xz, yy, yz;
};

// The geometry of the key cube: a node at `level` with key `prefix` is the
// cube of side side·2^−level at corner + (its three coordinates)·that side.
struct CubeFrame {
  std::array<double, 3> corner;
  double side;
};

// Moments of the leaf holding particles [first, last) of x, y, z, m.
template <class Real>
[[gnu::noinline]] NodeMoments leaf_moments(const Real* x, const Real* y, const Real* z, const Real* m,
                                           std::uint32_t first, std::uint32_t last, std::uint8_t level,
                                           std::uint64_t prefix, const CubeFrame& frame, bool quadrupole);

// Moments of an internal node from its children's, children[0 .. count) in child order.
[[gnu::noinline]] NodeMoments parent_moments(const NodeMoments* children, std::size_t count, std::uint8_t level,
                                             std::uint64_t prefix, const CubeFrame& frame, bool quadrupole);

// Writes node n of t: centre of mass, mass, quadrupole in Real and the squared
// opening radius of the settings' criterion.
template <class Real>
[[gnu::noinline]] void store_node(const NodeMoments& r, std::uint8_t level, std::uint64_t prefix,
                                  const CubeFrame& frame, const LinearTreeSettings& settings, LinearNodes<Real>& t,
                                  std::size_t n);

extern template NodeMoments leaf_moments<float>(const float*, const float*, const float*, const float*,
                                                std::uint32_t, std::uint32_t, std::uint8_t, std::uint64_t,
                                                const CubeFrame&, bool);
extern template NodeMoments leaf_moments<double>(const double*, const double*, const double*, const double*,
                                                 std::uint32_t, std::uint32_t, std::uint8_t, std::uint64_t,
                                                 const CubeFrame&, bool);
extern template void store_node<float>(const NodeMoments&, std::uint8_t, std::uint64_t, const CubeFrame&,
                                       const LinearTreeSettings&, LinearNodes<float>&, std::size_t);
extern template void store_node<double>(const NodeMoments&, std::uint8_t, std::uint64_t, const CubeFrame&,
                                        const LinearTreeSettings&, LinearNodes<double>&, std::size_t);

}  // namespace swirl::gravity::detail
