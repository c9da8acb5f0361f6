// dist::BlockFold (dist/block_fold.hpp) on 1-4 ranks: sums and maxima of
// per-particle contributions, some particles contributing nothing, give the
// bits of the one-rank fold for any cut of the order into ranks (cuts inside
// blocks, on block starts, ranks holding less than one block, empty ranks),
// and the one-rank fold is parallel::reduce_blocks over the same
// contributions, for values whose sum depends on the order of the additions.
#include "swirl/dist/block_fold.hpp"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "dist/block_cuts.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::dist {
namespace {

std::vector<double> values_for(std::size_t n) { return test::order_sensitive_values(n, 777); }

constexpr std::array<FoldOp, 3> kOps{FoldOp::Sum, FoldOp::Max, FoldOp::Sum};

// Particle i (global) contributes (v, |v|, 1) unless i % 7 == 3.
bool contributes(std::size_t global) { return global % 7 != 3; }

// The documented one-rank meaning: reduce_blocks over the contributions.
std::array<double, 3> reference(const std::vector<double>& v, std::size_t block_size) {
  using T = std::array<double, 3>;
  return parallel::reduce_blocks(
      "test", v.size(), block_size, T{},
      [&](std::size_t b, std::size_t e) {
        T s{};
        for (std::size_t i = b; i < e; ++i)
          if (contributes(i)) s = {s[0] + v[i], std::max(s[1], std::abs(v[i])), s[2] + 1.0};
        return s;
      },
      [](T a, const T& b) { return T{a[0] + b[0], std::max(a[1], b[1]), a[2] + b[2]}; });
}

TEST(BlockFold, IsTheOneRankBlockFoldForAnyCuts) {
  const Communicator& comm = Communicator::world();
  const auto ranks = static_cast<std::size_t>(comm.size()), r = static_cast<std::size_t>(comm.rank());
  int checked = 0, order_matters = 0;
  for (const std::size_t n : {0, 1, 5, 64, 1000, 4099}) {
    const std::vector<double> v = values_for(n);
    for (const std::size_t bs : {1, 3, 64, 1024}) {
      const auto want = reference(v, bs);
      double plain = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (contributes(i)) plain += v[i];
      if (plain != want[0]) ++order_matters;
      for (int pattern = 0; pattern < test::kBlockCutPatterns; ++pattern) {
        const std::vector<std::size_t> start = test::block_cut_starts(n, ranks, bs, pattern);
        const BlockFold fold{&comm, start[r], bs};
        const auto got = fold("test", start[r + 1] - start[r], kOps, [&](std::size_t i, std::array<double, 3>& c) {
          const std::size_t g = start[r] + i;
          if (!contributes(g)) return false;
          c = {v[g], std::abs(v[g]), 1.0};
          return true;
        });
        for (std::size_t j = 0; j < 3; ++j)
          EXPECT_EQ(std::bit_cast<std::uint64_t>(got[j]), std::bit_cast<std::uint64_t>(want[j]))
              << "n = " << n << ", block " << bs << ", cut pattern " << pattern << ", component " << j << ": "
              << got[j] << " != " << want[j];
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 6 * 4 * 4);
  EXPECT_GT(order_matters, 0);  // the test's values do tell the orders apart
}

TEST(BlockFold, SumIsOneComponent) {
  const Communicator& comm = Communicator::world();
  const std::vector<double> v = values_for(3000);
  const auto ranks = std::uint64_t(comm.size()), r = std::uint64_t(comm.rank());
  const std::uint64_t first = v.size() * r / ranks, last = v.size() * (r + 1) / ranks;
  const double got = BlockFold{&comm, first, 100}.sum("test", last - first, [&](std::size_t i) { return v[first + i]; });
  const double want = BlockFold::one_rank(100).sum("test", v.size(), [&](std::size_t i) { return v[i]; });
  EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want));
}

}  // namespace
}  // namespace swirl::dist
