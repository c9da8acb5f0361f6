// Grid cells and the spatial hash of Teschner et al. 2003 (the seed's [42]),
// as the thesis uses them (section 4.2.1):
//
//   cell = floor(x / h) per axis                  (cell length = support radius h)
//   hash = ((uint32)i·P1 ^ (uint32)j·P2 ^ (uint32)k·P3) mod M
//
// with P1 = 73856093, P2 = 19349663, P3 = 83492791 and unsigned wrap-around
// arithmetic (the formula itself is missing from the seed's text).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace swirl::spatial {

inline constexpr std::uint32_t kP1 = 73856093u;
inline constexpr std::uint32_t kP2 = 19349663u;
inline constexpr std::uint32_t kP3 = 83492791u;

// Integer coordinates of a grid cell.
struct Cell {
  std::int32_t i = 0, j = 0, k = 0;
  friend constexpr bool operator==(const Cell&, const Cell&) = default;
};

// floor(x / h) as an integer, clamped to the int32 range (a coordinate that far
// out only shares its cell with equally far particles, so clamping is safe).
template <class Real>
inline std::int32_t cell_coordinate(Real x, Real h) {
  const double c = std::floor(static_cast<double>(x) / static_cast<double>(h));
  return static_cast<std::int32_t>(std::clamp(c, -2147483648.0, 2147483647.0));
}

template <class Real>
inline Cell cell_of(Real x, Real y, Real z, Real h) {
  return {cell_coordinate(x, h), cell_coordinate(y, h), cell_coordinate(z, h)};
}

// Teschner's hash of a cell into [0, buckets); buckets ≥ 1.
inline std::uint32_t hash_cell(const Cell& c, std::uint32_t buckets) {
  const std::uint32_t h = (static_cast<std::uint32_t>(c.i) * kP1) ^ (static_cast<std::uint32_t>(c.j) * kP2) ^
                          (static_cast<std::uint32_t>(c.k) * kP3);
  return h % buckets;
}

}  // namespace swirl::spatial
