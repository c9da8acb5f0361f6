// The paper's timing experiment as a library call (Table 1 phases), and the
// force error of a tree against the direct sum (Figures 14-15's accuracy side).
#include <gtest/gtest.h>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/bench.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/initial_conditions.hpp"
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
      // The paper-table harness builds the paper's trees: a leaf per particle.
      EXPECT_GT(r.nodes, 1024u);
      EXPECT_EQ(r.trees > 1, scheme != Scheme::Global);
      EXPECT_EQ(parallel::thread_count(), saved);
    }
  }
}

TEST(BenchTest, SummarizeErrorsTakesLowerMedianAndNearestRankPercentile) {
  std::vector<double> none;
  EXPECT_EQ(summarize_errors(none).max, 0);
  std::vector<double> five{5, 1, 3, 2, 4};
  const ForceError a = summarize_errors(five);
  EXPECT_EQ(a.median, 3);
  EXPECT_EQ(a.p99, 5);
  EXPECT_EQ(a.max, 5);
  std::vector<double> hundred;
  for (int i = 100; i >= 1; --i) hundred.push_back(i);
  const ForceError b = summarize_errors(hundred);
  EXPECT_EQ(b.median, 50);
  EXPECT_EQ(b.p99, 99);
  EXPECT_EQ(b.max, 100);
}

// The fast path (one direct sum for all cases, errors in parallel blocks)
// against the slow twin: the tree and the direct sum computed here, the
// errors by the test helper.
TEST(BenchTest, ForceErrorsMatchTheirSlowTwinForAnyThreadCount) {
  BenchSettings b;
  b.n = 700;
  b.seed = 3;
  std::vector<ForceErrorCase> cases;
  for (Scheme scheme : testing::kSchemes)
    for (double lambda : {0.0, 0.3, 0.6, 0.9}) cases.push_back({scheme, lambda});
  const ParticleSet<double> p = plummer<double>(b.n, b.seed);
  GravityField<double> exact;
  direct_sum(p, b.softening, 64, exact);
  std::vector<ForceError> first;
  for (int threads : {1, 2, 3}) {
    b.threads = threads;
    const auto errors = force_errors(b, cases);
    ASSERT_EQ(errors.size(), cases.size());
    if (first.empty()) first = errors;
    for (std::size_t c = 0; c < cases.size(); ++c) {
      GravitySettings g;
      g.scheme = cases[c].scheme;
      g.tree = Tree::Paper;  // the paper-table harness measures the paper's tree
      g.opening = cases[c].opening;
      g.softening = b.softening;
      const auto e = testing::relative_errors(testing::tree_field(p, g), exact, exact);
      EXPECT_EQ(errors[c].median, e[(e.size() - 1) / 2]) << c;
      EXPECT_EQ(errors[c].max, e.back()) << c;
      EXPECT_EQ(errors[c].p99, e[693 - 1]) << c;  // ceil(0.99 · 700) = 693
      EXPECT_GT(errors[c].mean_nodes_visited, 0);
      EXPECT_EQ(errors[c].median, first[c].median) << "threads " << threads;
      EXPECT_EQ(errors[c].p99, first[c].p99) << "threads " << threads;
      if (cases[c].opening == 0) {
        EXPECT_LT(errors[c].max, 1e-12) << "lambda = 0 is the direct sum";
      }
    }
    // Opening fewer nodes costs accuracy.
    for (std::size_t c = 1; c < cases.size(); ++c)
      if (cases[c].scheme == cases[c - 1].scheme) {
        EXPECT_GT(errors[c].median, errors[c - 1].median) << c;
      }
  }
}

TEST(BenchTest, ForceErrorsRefuseBadCases) {
  BenchSettings b;
  b.n = 64;
  EXPECT_THROW(force_errors(b, {{Scheme::Global, 1.5}}), std::invalid_argument);
  b.threads = 0;
  EXPECT_THROW(force_errors(b, {{Scheme::Global, 0.5}}), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::gravity
