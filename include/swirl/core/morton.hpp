// Morton (Z-order) keys: the bits of three 21-bit integer coordinates
// interleaved, bit k of x at key bit 3k, of y at 3k + 1, of z at 3k + 2 —
// 63 bits in all. Shared by the SPH grid's Morton cell order
// (spatial/cell_order.hpp) and the linear octree's particle keys
// (gravity/linear_octree.hpp), whose octant digits are these bit triples.
#pragma once

#include <cstdint>

namespace swirl {

// The 21 low bits of v spread to every third bit (bit k → bit 3k).
constexpr std::uint64_t morton_spread(std::uint64_t v) {
  v &= 0x1fffffu;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// The inverse of morton_spread: bits 0, 3, 6, ... of v packed into 21 bits.
constexpr std::uint64_t morton_compact(std::uint64_t v) {
  v &= 0x1249249249249249ULL;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ULL;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00fULL;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffULL;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffULL;
  v = (v ^ (v >> 32)) & 0x1fffffULL;
  return v;
}

constexpr std::uint64_t morton_key(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  return morton_spread(x) | morton_spread(y) << 1 | morton_spread(z) << 2;
}

static_assert(morton_key(1, 0, 0) == 1 && morton_key(0, 1, 0) == 2 && morton_key(0, 0, 1) == 4);
static_assert(morton_compact(morton_spread(0x1abcdeu)) == 0x1abcdeu);
static_assert(morton_compact(morton_key(5, 6, 7) >> 1) == 6);

}  // namespace swirl
