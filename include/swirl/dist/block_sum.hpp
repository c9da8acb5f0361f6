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
// block. block_ordered_sum() gives the same bits on any rank count: each rank
// sends (one all-gather)
//   - its head: the values of the block that started on an earlier rank
//     (at most B − 1 of them), raw;
//   - for every block that starts on it, the sum of its part of that block
//     from 0, in order (the last one may continue on the next ranks);
// and every rank folds the records in rank order: a head's values are added
// one at a time to the open block's partial sum (the one-rank block sum
// continued exactly), a block start closes the previous block into the total.
// The traffic per rank and call is at most B − 1 + n_r/B + 2 doubles and two
// integers. One rank (or no MPI): the local sum, the same fold.
// The values must be finite or not as the one-rank values are; nothing here
// rounds differently from reduce_blocks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <vector>

#include "swirl/dist/communicator.hpp"

namespace swirl::dist {

// Collective. values: this rank's particles' values in memory order; first:
// the global index of the first; block_size: the one-rank run's B (≥ 1).
inline double block_ordered_sum(const Communicator& comm, std::uint64_t first, std::span<const double> values,
                                std::size_t block_size) {
  if (block_size == 0) throw std::invalid_argument("block_ordered_sum: block size 0");
  const std::uint64_t B = block_size, n = values.size(), end = first + n;
  const std::uint64_t next_start = (first + B - 1) / B * B;  // the first block start ≥ first
  const std::uint64_t head_end = next_start < end ? next_start : end;
  // The record: head count, head values, partial count, partials.
  std::vector<double> head(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(head_end - first));
  std::vector<double> partials;
  for (std::uint64_t s = next_start; s < end; s += B) {
    const std::uint64_t e = s + B < end ? s + B : end;
    double t = 0;
    for (std::uint64_t i = s; i < e; ++i) t += values[static_cast<std::size_t>(i - first)];
    partials.push_back(t);
  }
  auto encode = [](const std::vector<double>& h, const std::vector<double>& p) {
    Bytes b(2 * sizeof(std::uint64_t) + (h.size() + p.size()) * sizeof(double));
    std::byte* at = b.data();
    const std::uint64_t counts[2] = {h.size(), p.size()};
    std::memcpy(at, counts, sizeof(counts));
    at += sizeof(counts);
    if (!h.empty()) std::memcpy(at, h.data(), h.size() * sizeof(double));
    at += h.size() * sizeof(double);
    if (!p.empty()) std::memcpy(at, p.data(), p.size() * sizeof(double));
    return b;
  };
  double total = 0, open_sum = 0;
  bool open = false;
  auto fold = [&](std::span<const double> h, std::span<const double> p) {
    for (const double v : h) open_sum += v;
    for (const double s : p) {
      if (open) total += open_sum;
      open_sum = s;
      open = true;
    }
  };
  if (!comm.distributed()) {
    fold(head, partials);
  } else {
    for (const Bytes& b : comm.all_gather(encode(head, partials))) {
      std::uint64_t counts[2] = {0, 0};
      if (b.size() < sizeof(counts)) throw std::runtime_error("block_ordered_sum: a rank sent a short record");
      std::memcpy(counts, b.data(), sizeof(counts));
      if (b.size() != sizeof(counts) + (counts[0] + counts[1]) * sizeof(double))
        throw std::runtime_error("block_ordered_sum: a rank sent a record of the wrong size");
      std::vector<double> h(counts[0]), p(counts[1]);
      const std::byte* at = b.data() + sizeof(counts);
      if (!h.empty()) std::memcpy(h.data(), at, h.size() * sizeof(double));
      at += h.size() * sizeof(double);
      if (!p.empty()) std::memcpy(p.data(), at, p.size() * sizeof(double));
      fold(h, p);
    }
  }
  if (open) total += open_sum;
  return total;
}

}  // namespace swirl::dist
