// block_ordered_sum: the one-rank block-order sum of a per-particle value,
// computed on ranks (docs/design/mpi.md, "Reductions, the step and
// diagnostics"; issue 19 item 5).
//
// On one rank, parallel::reduce_blocks(n, B, 0.0, block, +) sums particle
// values as
//   total = (((0 + s_0) + s_1) + ...),  s_k = (((0 + v_kB) + v_kB+1) + ...)
// over the blocks [kB, (k+1)B) of the memory order: a floating-point sum whose
// bits depend on where the blocks start. On ranks, rank r holds the range
// [first_r, first_r + n_r) of that order, and a cut generally falls inside a
// block. block_ordered_sum() gives the same bits on any rank count: it is
// BlockFold::sum (dist/block_fold.hpp) over values already in memory, which
// sends the raw values of the block a lower rank opened (at most B − 1) and
// the partial sums of the blocks that start on this rank, and folds them in
// rank order. One rank (or no MPI): the same fold, locally.
// The values must be finite or not as the one-rank values are; nothing here
// rounds differently from reduce_blocks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "swirl/dist/block_fold.hpp"
#include "swirl/dist/communicator.hpp"

namespace swirl::dist {

// Collective. values: this rank's particles' values in memory order; first:
// the global index of the first; block_size: the one-rank run's B (≥ 1).
inline double block_ordered_sum(const Communicator& comm, std::uint64_t first, std::span<const double> values,
                                std::size_t block_size) {
  return BlockFold{&comm, first, block_size}.sum("block_ordered_sum", values.size(),
                                                 [&](std::size_t i) { return values[i]; });
}

}  // namespace swirl::dist
