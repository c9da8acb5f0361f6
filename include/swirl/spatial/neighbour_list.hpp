// Interaction lists in CSR form (the thesis's interaction lists, section 4.2.3):
// row r belongs to particle row_particle[r]; its neighbours are
// neighbour[offsets[r] .. offsets[r+1]) with their squared distances in r2.
// Rows and the neighbours within a row are in a deterministic order (the order
// of the search that made them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace swirl::spatial {

template <class Real>
struct NeighbourList {
  std::vector<std::uint32_t> row_particle;  // particle index of each row
  std::vector<std::size_t> offsets;         // rows() + 1 entries
  std::vector<std::uint32_t> neighbour;      // particle index j of each interaction
  std::vector<Real> r2;                     // |x_i − x_j|² of each interaction

  std::size_t rows() const { return row_particle.size(); }
  std::size_t interactions() const { return neighbour.size(); }
  std::size_t count(std::size_t row) const { return offsets[row + 1] - offsets[row]; }
};

}  // namespace swirl::spatial
