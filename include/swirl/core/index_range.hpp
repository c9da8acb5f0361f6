// IndexRange: a half-open range [begin, end) of particle indices in memory
// order, 32 bits each (swirl's particle counts stay below 2^31). The one
// range type of the cell grid, its occupied-cell table and the SPH kernels,
// so a cell's neighbour ranges go from the grid to a SIMD kernel uncopied.
#pragma once

#include <cstdint>

namespace swirl {

struct IndexRange {
  std::uint32_t begin = 0, end = 0;
};

}  // namespace swirl
