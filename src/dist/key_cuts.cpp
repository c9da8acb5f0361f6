#include "swirl/dist/key_cuts.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "swirl/dist/key_order.hpp"

namespace swirl::dist {

std::vector<std::uint64_t> balanced_cut_keys(const Communicator& comm, std::span<const std::uint64_t> keys,
                                             std::span<const std::uint64_t> costs, int depth) {
  if (keys.size() != costs.size()) throw std::invalid_argument("balanced_cut_keys: one cost per key is needed");
  if (depth < 0 || depth > kKeyDepth)
    throw std::invalid_argument("balanced_cut_keys: depth " + std::to_string(depth) + " is outside 0.." +
                                std::to_string(kKeyDepth));
  // The local keys sorted, and prefix sums of their costs in that order: the
  // local cost below a key is then one binary search.
  std::vector<std::size_t> order(keys.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  std::vector<std::uint64_t> sorted_keys(keys.size());
  std::vector<std::uint64_t> below(keys.size() + 1, 0);
  for (std::size_t i = 0; i < order.size(); ++i) {
    sorted_keys[i] = keys[order[i]];
    below[i + 1] = below[i] + costs[order[i]];
  }
  const std::uint64_t total = comm.sum(below.back());
  const auto ranks = static_cast<std::uint64_t>(comm.size());
  if (total > std::numeric_limits<std::uint64_t>::max() / ranks)
    throw std::overflow_error("balanced_cut_keys: the total cost is too large to split exactly");
  auto local_cost_below = [&](std::uint64_t key) {
    return below[static_cast<std::size_t>(std::lower_bound(sorted_keys.begin(), sorted_keys.end(), key) -
                                          sorted_keys.begin())];
  };

  // Boundary j is the key j << shift, j in [0, 2^(3·depth)].
  const unsigned shift = 3u * static_cast<unsigned>(kKeyDepth - depth);
  const std::uint64_t boundaries = std::uint64_t{1} << (3u * static_cast<unsigned>(depth));
  const std::size_t cuts = static_cast<std::size_t>(ranks - 1);
  // Cut r+1 is the smallest j with cost_below(j)·size ≥ (r+1)·total: search in [lo, hi].
  std::vector<std::uint64_t> lo(cuts, 0), hi(cuts, boundaries);
  std::vector<std::uint64_t> sums(cuts);
  for (bool searching = cuts > 0; searching;) {
    searching = false;
    for (std::size_t r = 0; r < cuts; ++r) {
      const std::uint64_t mid = lo[r] + (hi[r] - lo[r]) / 2;
      sums[r] = lo[r] < hi[r] ? local_cost_below(mid << shift) : 0;
    }
    comm.sum(sums);
    for (std::size_t r = 0; r < cuts; ++r) {
      if (lo[r] >= hi[r]) continue;
      const std::uint64_t mid = lo[r] + (hi[r] - lo[r]) / 2;
      if (sums[r] * ranks >= (r + 1) * total)
        hi[r] = mid;
      else
        lo[r] = mid + 1;
      searching = searching || lo[r] < hi[r];
    }
  }
  std::vector<std::uint64_t> cut_keys(cuts);
  for (std::size_t r = 0; r < cuts; ++r)
    cut_keys[r] = lo[r] == boundaries ? std::numeric_limits<std::uint64_t>::max() : lo[r] << shift;
  return cut_keys;
}

std::vector<std::uint64_t> cost_per_rank(const Communicator& comm, std::span<const std::uint64_t> keys,
                                         std::span<const std::uint64_t> costs,
                                         std::span<const std::uint64_t> cut_keys) {
  if (keys.size() != costs.size()) throw std::invalid_argument("cost_per_rank: one cost per key is needed");
  std::vector<std::uint64_t> per_rank(static_cast<std::size_t>(comm.size()), 0);
  sum_per_rank(keys, cut_keys, [&](std::size_t i) { return costs[i]; }, per_rank);
  comm.sum(per_rank);
  return per_rank;
}

double imbalance(std::span<const std::uint64_t> rank_costs) {
  std::uint64_t total = 0, largest = 0;
  for (std::uint64_t c : rank_costs) {
    total += c;
    largest = std::max(largest, c);
  }
  if (total == 0) return 1.0;
  return static_cast<double>(largest) * static_cast<double>(rank_costs.size()) / static_cast<double>(total);
}

}  // namespace swirl::dist
