// What the block-order reduction tests (block_sum_test.cpp,
// block_fold_test.cpp) reduce and how they cut it into ranks.
//
// order_sensitive_values: n values over 20 orders of magnitude with both
// signs, so that a sum in another order gives other bits.
// block_cut_starts: rank k holds [start[k], start[k+1]) of n particles.
// Pattern 0: even shares; 1: everything on rank 0, the others empty; 2: cuts
// on block starts (block size bs); 3: ranks of a few particles each inside
// the first blocks. kBlockCutPatterns of them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace swirl::dist::test {

inline std::vector<double> order_sensitive_values(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed + n);
  std::uniform_real_distribution<double> mantissa(-1, 1), exponent(-10, 10);
  std::vector<double> v(n);
  for (double& x : v) x = mantissa(rng) * std::pow(10.0, exponent(rng));
  return v;
}

inline constexpr int kBlockCutPatterns = 4;

inline std::vector<std::size_t> block_cut_starts(std::size_t n, std::size_t ranks, std::size_t bs, int pattern) {
  std::vector<std::size_t> start(ranks + 1, n);
  for (std::size_t k = 0; k < ranks; ++k) {
    switch (pattern) {
      case 0: start[k] = n * k / ranks; break;
      case 1: start[k] = k == 0 ? 0 : n; break;
      case 2: start[k] = std::min(n, (n * k / ranks) / bs * bs); break;
      default: start[k] = std::min(n, k == 0 ? 0 : bs / 2 + 2 * k); break;
    }
  }
  for (std::size_t k = 1; k <= ranks; ++k) start[k] = std::max(start[k], start[k - 1]);
  return start;
}

}  // namespace swirl::dist::test
