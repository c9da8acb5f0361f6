// block_ordered_sum (dist/block_sum.hpp) on 1-4 ranks: the bits of the
// one-rank parallel::reduce_blocks sum for any cut of the order into ranks
// (cuts inside blocks, on block starts, ranks holding less than one block,
// empty ranks), values whose sum depends on the order of the additions.
#include "swirl/dist/block_sum.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <vector>

#include "dist/block_cuts.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::dist {
namespace {

std::vector<double> values_for(std::size_t n) { return test::order_sensitive_values(n, 12345); }

double one_rank_sum(const std::vector<double>& v, std::size_t block_size) {
  return parallel::reduce_blocks(
      "test", v.size(), block_size, 0.0,
      [&](std::size_t b, std::size_t e) {
        double t = 0;
        for (std::size_t i = b; i < e; ++i) t += v[i];
        return t;
      },
      [](double a, double b) { return a + b; });
}

TEST(BlockOrderedSum, IsTheOneRankBlockSumForAnyCuts) {
  const Communicator& comm = Communicator::world();
  const auto ranks = static_cast<std::size_t>(comm.size()), r = static_cast<std::size_t>(comm.rank());
  int checked = 0, order_matters = 0;
  for (const std::size_t n : {0, 1, 5, 64, 1000, 4099}) {
    const std::vector<double> v = values_for(n);
    for (const std::size_t bs : {1, 3, 64, 1024}) {
      const double want = one_rank_sum(v, bs);
      // A plain sequential sum, to show that the blocks matter for these values.
      double plain = 0;
      for (const double x : v) plain += x;
      if (plain != want) ++order_matters;
      // Cut patterns (block_cuts.hpp): even shares; everything on one rank;
      // block-aligned cuts; ranks of a few particles inside a block.
      for (int pattern = 0; pattern < test::kBlockCutPatterns; ++pattern) {
        const std::vector<std::size_t> start = test::block_cut_starts(n, ranks, bs, pattern);
        const std::span<const double> mine(v.data() + start[r], start[r + 1] - start[r]);
        const double got = block_ordered_sum(comm, start[r], mine, bs);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want))
            << "n = " << n << ", block " << bs << ", cut pattern " << pattern << ": " << got << " != " << want;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 6 * 4 * 4);
  EXPECT_GT(order_matters, 0);  // the test's values do tell the orders apart
}

}  // namespace
}  // namespace swirl::dist
