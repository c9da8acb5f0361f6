// BlockFold: the one-rank block-order reduction of per-particle values
// (parallel::reduce_blocks' bits, for any thread count) computed on the ranks
// of a run, for the diagnostics that are sums and maxima over the particles
// (docs/design/mpi.md, "Reductions, the step and diagnostics"; issue 19
// items 5 and 6): the ranks need not gather the set to log its energy.
//
// A reduction of K components, each a sum or a maximum, of one contribution
// per particle (a particle may contribute nothing). On one rank it is
//   reduce_blocks(n, B, zeros, block, combine),
//   block(b, e): s = zeros; s_j = op_j(s_j, c_j(i)) for i in [b, e) in order,
//   combine(a, b) = op_j(a_j, b_j) per component,
// with op_j either a + b or std::max(a, b). On ranks, rank r holds the range
// [first_r, first_r + n_r) of the one-rank order, and a block [kB, (k+1)B)
// may be cut by rank boundaries. Each rank sends (one all-gather) its head —
// the contributions, raw, of its particles in the block that began on an
// earlier rank — and the partial of every block that begins on it, over its
// own part; every rank then folds the
// records in rank order: a head's contributions continue the open block's
// fold exactly as the one-rank block function would, a block start closes the
// open block into the total. The same bits for any rank and thread count.
// Traffic per rank and call: at most (B − 1 + n_r/B + 1)·K doubles.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/dist/communicator.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::dist {

enum class FoldOp : std::uint8_t { Sum, Max };

// Where a rank's particles sit in the one-rank order, and that run's block
// size: what a reduction over them needs. The default is one rank.
struct BlockFold {
  const Communicator* ranks = nullptr;  // null (or a single rank): the particles are the whole set
  std::uint64_t first = 0;              // the global index of this rank's first particle
  std::size_t block_size = 1024;        // B of the one-rank run (≥ 1)

  static BlockFold one_rank(std::size_t block_size) { return {nullptr, 0, block_size}; }
  bool distributed() const { return ranks != nullptr && ranks->distributed(); }

  // The reduction described above over this rank's n particles: contribution(i,
  // c) fills c (K values) for particle i (0 ≤ i < n, in memory order) and
  // returns false when the particle contributes nothing. Collective on ranks
  // (the result on every rank); `kernel` names it in errors.
  template <std::size_t K, class Contribution>
  std::array<double, K> operator()(std::string_view kernel, std::size_t n, const std::array<FoldOp, K>& ops,
                                   Contribution&& contribution) const {
    using Values = std::array<double, K>;
    if (block_size == 0) throw std::invalid_argument("BlockFold: block size 0");
    const auto apply = [&ops](Values& s, const Values& c) {
      for (std::size_t j = 0; j < K; ++j) s[j] = ops[j] == FoldOp::Sum ? s[j] + c[j] : std::max(s[j], c[j]);
    };
    // The blocks of the one-rank order that this rank's particles fall in:
    // local particle i is at global first + i, and block k of this call
    // covers the global block of index first/B + k (the first of them, the
    // head, may have begun on an earlier rank). Every block, the head too,
    // writes its particles' contributions to memory and folds them from
    // there, through the one code path: the contributions are rounded the
    // same way whichever rank and thread computes them (a sum fused into one
    // multiply-add in one place and not in another would not be).
    const std::size_t shift = static_cast<std::size_t>(first % block_size);
    std::vector<Values> partials(parallel::block_count(n + shift, block_size));
    std::vector<double> head;
    parallel::for_blocks(kernel, n + shift, block_size, [&](std::size_t vb, std::size_t ve, std::size_t k) {
      const std::size_t b = std::max(vb, shift) - shift, e = ve - shift;
      std::vector<Values> c(e - b);
      std::vector<unsigned char> counts(e - b);
      for (std::size_t i = b; i < e; ++i) counts[i - b] = contribution(i, c[i - b]) ? 1 : 0;
      if (k == 0 && shift > 0) {  // the head: sent raw, folded into the block a lower rank opened
        for (std::size_t i = 0; i < c.size(); ++i)
          if (counts[i]) head.insert(head.end(), c[i].begin(), c[i].end());
        return;
      }
      Values s{};
      for (std::size_t i = 0; i < c.size(); ++i)
        if (counts[i]) apply(s, c[i]);
      partials[k] = s;
    });
    if (shift > 0 && !partials.empty()) partials.erase(partials.begin());

    Values total{}, open{};
    bool is_open = false;
    const auto fold = [&](const double* heads, std::uint64_t n_heads, const double* starts, std::uint64_t n_starts) {
      for (std::uint64_t h = 0; h < n_heads; ++h) {
        Values c;
        std::memcpy(c.data(), heads + h * K, sizeof(Values));
        apply(open, c);
      }
      for (std::uint64_t p = 0; p < n_starts; ++p) {
        if (is_open) apply(total, open);
        std::memcpy(open.data(), starts + p * K, sizeof(Values));
        is_open = true;
      }
    };
    if (!distributed()) {
      fold(head.data(), head.size() / K, partials.empty() ? nullptr : partials.front().data(), partials.size());
    } else {
      const std::uint64_t counts[2] = {head.size() / K, partials.size()};
      Bytes mine(sizeof(counts) + (head.size() + partials.size() * K) * sizeof(double));
      std::memcpy(mine.data(), counts, sizeof(counts));
      if (!head.empty()) std::memcpy(mine.data() + sizeof(counts), head.data(), head.size() * sizeof(double));
      if (!partials.empty())
        std::memcpy(mine.data() + sizeof(counts) + head.size() * sizeof(double), partials.data(),
                    partials.size() * sizeof(Values));
      for (const Bytes& record : ranks->all_gather(mine)) {
        std::uint64_t n_records[2] = {0, 0};
        if (record.size() < sizeof(n_records))
          throw std::runtime_error(std::string(kernel) + ": a rank sent a short block-fold record");
        std::memcpy(n_records, record.data(), sizeof(n_records));
        if (record.size() != sizeof(n_records) + (n_records[0] + n_records[1]) * sizeof(Values))
          throw std::runtime_error(std::string(kernel) + ": a rank sent a block-fold record of the wrong size");
        std::vector<double> values((n_records[0] + n_records[1]) * K);
        if (!values.empty()) std::memcpy(values.data(), record.data() + sizeof(n_records), values.size() * sizeof(double));
        fold(values.data(), n_records[0], values.data() + n_records[0] * K, n_records[1]);
      }
    }
    if (is_open) apply(total, open);
    return total;
  }

  // One sum (K = 1) of value(i), every particle contributing.
  template <class Value>
  double sum(std::string_view kernel, std::size_t n, Value&& value) const {
    return (*this)(kernel, n, std::array<FoldOp, 1>{FoldOp::Sum}, [&](std::size_t i, std::array<double, 1>& c) {
      c[0] = value(i);
      return true;
    })[0];
  }
};

}  // namespace swirl::dist
