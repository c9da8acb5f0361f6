// The paper's timing experiment as a library call (Table 1 phases).
#include <gtest/gtest.h>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/bench.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {
namespace {

TEST(BenchTest, TimesEveryPhaseAndRestoresTheThreadCount) {
  const int saved = parallel::thread_count();
  for (Scheme scheme : testing::kSchemes) {
    for (bool single : {false, true}) {
      BenchSettings b;
      b.scheme = scheme;
      b.n = 1024;
      b.iterations = 3;
      b.threads = 2;
      b.single_precision = single;
      const BenchResult r = time_iterations(b);
      EXPECT_GT(r.tree_build, 0) << to_string(scheme);
      EXPECT_GT(r.force, 0);
      EXPECT_GT(r.update, 0);
      EXPECT_GE(r.total, r.tree_build + r.force + r.update);
      EXPECT_GT(r.mean_nodes_visited, 0);
      EXPECT_GT(r.nodes, 1024u);
      EXPECT_EQ(r.trees > 1, scheme != Scheme::global);
      EXPECT_EQ(parallel::thread_count(), saved);
    }
  }
}

}  // namespace
}  // namespace swirl::gravity
