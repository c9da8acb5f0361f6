// ThreadGovernor against step-time models: it keeps every thread on a quiet
// machine (probing rarely), moves to fewer threads when they are faster (a
// core busy with another process), comes back when the core frees up, and
// ignores single slow steps.
#include "swirl/parallel/thread_governor.hpp"

#include <gtest/gtest.h>

#include <functional>

namespace {

using swirl::parallel::ThreadGovernor;

// Runs `steps` steps whose time at n threads is step_time(n, step).
void run(ThreadGovernor& g, std::uint64_t steps, const std::function<double(int, std::uint64_t)>& step_time,
         std::uint64_t first = 0) {
  for (std::uint64_t s = first; s < first + steps; ++s) g.record(step_time(g.threads(), s));
}

double quiet(int n, std::uint64_t) { return 1.0 / n; }     // perfect scaling
double busy(int n, std::uint64_t) { return n == 1 ? 1.0 : 1.6; }  // 2 threads wait at every barrier

TEST(ThreadGovernor, AQuietMachineKeepsEveryThreadAndRarelyProbes) {
  ThreadGovernor g(2);
  run(g, 20000, quiet);
  EXPECT_EQ(g.threads(), 2);
  EXPECT_EQ(g.moves(), 0u);
  // Probes back off to one per max_wait (1024) steps: well under 1 % of the steps.
  EXPECT_LT(double(g.steps_below_max()) / double(g.steps()), 0.01) << g.steps_below_max();
  EXPECT_GT(g.steps_below_max(), 0u);  // it did look
}

TEST(ThreadGovernor, ABusyCoreMovesItToOneThreadWithinTheFirstProbe) {
  ThreadGovernor g(2);
  run(g, 64 + 7, busy);
  EXPECT_EQ(g.threads(), 1);
  run(g, 5000, busy, 71);
  EXPECT_EQ(g.threads(), 1);
  EXPECT_GT(double(g.steps_below_max()) / double(g.steps()), 0.95);
}

TEST(ThreadGovernor, ItComesBackWhenTheCoreIsFreeAgain) {
  ThreadGovernor g(2);
  run(g, 3000, busy);
  ASSERT_EQ(g.threads(), 1);
  // The wait between probes is at most 1024 steps, plus one probe.
  run(g, 1024 + 7 + 1, quiet, 3000);
  EXPECT_EQ(g.threads(), 2);
}

TEST(ThreadGovernor, SingleSlowStepsDoNotMoveIt) {
  ThreadGovernor g(2);
  // Every 10th step writes a frame and takes 20 times longer, at any thread count.
  run(g, 20000, [](int n, std::uint64_t s) { return (s % 10 == 9 ? 20.0 : 1.0) / n; });
  EXPECT_EQ(g.moves(), 0u);
  EXPECT_EQ(g.threads(), 2);
}

TEST(ThreadGovernor, ManyCoresSettleOnTheFastestCount) {
  ThreadGovernor g(8);
  // Four threads are best (say four of eight cores busy).
  run(g, 20000, [](int n, std::uint64_t) { return n <= 4 ? 1.0 / n : 0.4; });
  EXPECT_EQ(g.threads(), 4);
}

TEST(ThreadGovernor, OneThreadIsOneThread) {
  ThreadGovernor g(1);
  run(g, 1000, quiet);
  EXPECT_EQ(g.threads(), 1);
  EXPECT_EQ(g.steps_below_max(), 0u);
  EXPECT_THROW(ThreadGovernor(0), std::invalid_argument);
}

}  // namespace
