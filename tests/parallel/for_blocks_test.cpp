#include "swirl/parallel/for_blocks.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <thread>
#include <vector>

namespace {

using swirl::parallel::for_blocks;
using swirl::parallel::for_blocks_pinned;
using swirl::parallel::reduce_blocks;
using swirl::parallel::reduce_blocks_pinned;

TEST(ForBlocks, VisitsEveryIndexExactlyOnceInFixedBlocks) {
  for (int threads : {1, 2, 3}) {
    swirl::parallel::set_thread_count(threads);
    for (std::size_t n : {0ul, 1ul, 7ul, 64ul, 1000ul}) {
      std::vector<int> hits(n, 0);
      std::vector<std::size_t> block_of(n, 999);
      for_blocks("test", n, 7, [&](std::size_t b, std::size_t e, std::size_t block) {
        ASSERT_EQ(b, block * 7);
        ASSERT_LE(e - b, 7u);
        for (std::size_t i = b; i < e; ++i) {
          ++hits[i];
          block_of[i] = block;
        }
      });
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(hits[i], 1);
        EXPECT_EQ(block_of[i], i / 7);
      }
    }
  }
}

TEST(ForBlocks, UsesSeveralThreadsWhenAsked) {
  swirl::parallel::set_thread_count(2);
  // Blocks long enough that the worker wakes before the caller has run them all.
  std::atomic<int> max_seen{0};
  for (int attempt = 0; attempt < 100 && max_seen.load() < 1; ++attempt)
    for_blocks("test", 64, 1, [&](std::size_t, std::size_t, std::size_t) {
      const int t = swirl::parallel::thread_index();
      int prev = max_seen.load();
      while (t > prev && !max_seen.compare_exchange_weak(prev, t)) {}
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
  EXPECT_EQ(max_seen.load(), 1);
}

TEST(ReduceBlocks, FloatingPointSumIsBitIdenticalForAnyThreadCount) {
  std::vector<double> values(100000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::sin(double(i)) * 1e-3 + 1.0 / double(i + 1);
  auto sum_with = [&](int threads) {
    swirl::parallel::set_thread_count(threads);
    return reduce_blocks(
        "sum", values.size(), 97, 0.0,
        [&](std::size_t b, std::size_t e) {
          double s = 0;
          for (std::size_t i = b; i < e; ++i) s += values[i];
          return s;
        },
        [](double x, double y) { return x + y; });
  };
  const double one = sum_with(1);
  EXPECT_EQ(sum_with(2), one);
  EXPECT_EQ(sum_with(3), one);
  EXPECT_NEAR(one, 12.0900, 0.01);  // harmonic number H(1e5) ≈ 12.09 plus a small sine sum
}

TEST(ForBlocks, AnExceptionInABlockIsRethrownWithTheKernelName) {
  swirl::parallel::set_thread_count(2);
  try {
    for_blocks("my_kernel", 100, 10, [](std::size_t b, std::size_t, std::size_t) {
      if (b == 50) throw std::runtime_error("bad block");
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "my_kernel: bad block");
  }
  EXPECT_THROW(for_blocks("k", 10, 0, [](std::size_t, std::size_t, std::size_t) {}), std::invalid_argument);
  EXPECT_THROW(swirl::parallel::set_thread_count(0), std::invalid_argument);
}

TEST(ForBlocksPinned, VisitsEveryBlockOnceInContiguousRunsPerThread) {
  for (int threads : {1, 2, 3}) {
    swirl::parallel::set_thread_count(threads);
    const std::size_t n = 1000, size = 7;
    std::vector<int> hits(n, 0);
    for (int call = 0; call < 5; ++call)
      for_blocks_pinned("test", n, size, [&](std::size_t b, std::size_t e, std::size_t block) {
        ASSERT_EQ(b, block * size);
        for (std::size_t i = b; i < e; ++i) ++hits[i];
      });
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(hits[i], 5);
  }
}

// A thread held up inside a block (as when the operating system deschedules
// it) must not hold up the rest of its run: the others take those blocks.
// Whoever runs block 0 waits until every other block has run; with a plain
// static schedule the blocks after 0 of its run would wait for it, forever
// (the test gives up after 20 s and fails).
TEST(ForBlocksPinned, AHeldUpThreadsRemainingBlocksAreTakenByTheOthers) {
  for (int threads : {2, 3}) {
    swirl::parallel::set_thread_count(threads);
    const std::size_t n = 600, size = 10, blocks = swirl::parallel::block_count(n, size);
    std::atomic<std::size_t> done{0};
    std::atomic<bool> gave_up{false};
    std::vector<int> runs(blocks, 0);
    for_blocks_pinned("held_up", n, size, [&](std::size_t, std::size_t, std::size_t block) {
      if (block == 0) {
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while (done.load() < blocks - 1 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
        gave_up = done.load() < blocks - 1;
      }
      ++runs[block];
      ++done;
    });
    EXPECT_FALSE(gave_up) << threads << " threads";
    for (std::size_t b = 0; b < blocks; ++b) EXPECT_EQ(runs[b], 1) << b;
  }
}

// A reduction over bools: the per-block results must not share bytes (the
// packed std::vector<bool> made neighbouring blocks race and lose a true).
TEST(ReduceBlocksPinned, BoolResultsOfNeighbouringBlocksAreNeverLost) {
  for (int threads : {2, 3}) {
    swirl::parallel::set_thread_count(threads);
    for (std::size_t only = 0; only < 200; ++only) {
      const bool any = reduce_blocks_pinned(
          "any", 200, 1, false, [&](std::size_t b, std::size_t) { return b == only; },
          [](bool x, bool y) { return x || y; });
      ASSERT_TRUE(any) << only << ", " << threads << " threads";
    }
  }
}

TEST(ReduceBlocksPinned, EqualsTheWorkpoolsFoldBitForBit) {
  std::vector<double> values(50000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::cos(double(i)) / double(i + 1);
  const auto block_sum = [&](std::size_t b, std::size_t e) {
    double s = 0;
    for (std::size_t i = b; i < e; ++i) s += values[i];
    return s;
  };
  const auto add = [](double x, double y) { return x + y; };
  swirl::parallel::set_thread_count(1);
  const double reference = reduce_blocks("sum", values.size(), 61, 0.0, block_sum, add);
  for (int threads : {1, 2, 3}) {
    swirl::parallel::set_thread_count(threads);
    EXPECT_EQ(reduce_blocks_pinned("sum", values.size(), 61, 0.0, block_sum, add), reference) << threads;
  }
}

// The pool's promise: the caller waits for blocks, never for threads. With
// the workers held (as if the operating system never scheduled them), every
// loop still completes, on the caller alone, in both schedules; released,
// they take part again.
TEST(ThreadPool, ALoopCompletesWithoutWorkersThatNeverStarted) {
  auto& pool = swirl::parallel::pool();
  for (int threads : {2, 4}) {
    swirl::parallel::set_thread_count(threads);
    pool.hold_workers(true);
    for (int call = 0; call < 50; ++call) {
      std::vector<int> hits(300, 0);
      std::atomic<int> highest{0};
      const auto body = [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t i = b; i < e; ++i) ++hits[i];
        highest = std::max(highest.load(), swirl::parallel::thread_index());
      };
      if (call % 2) for_blocks("held", hits.size(), 3, body);
      else for_blocks_pinned("held", hits.size(), 3, body);
      for (int h : hits) ASSERT_EQ(h, 1);
      ASSERT_EQ(highest.load(), 0) << "a held worker ran a block";
    }
    pool.hold_workers(false);
  }
  std::atomic<int> highest{0};
  for (int attempt = 0; attempt < 100 && highest.load() == 0; ++attempt)
    for_blocks("released", 16, 1, [&](std::size_t, std::size_t, std::size_t) {
      highest = std::max(highest.load(), swirl::parallel::thread_index());
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
  EXPECT_GT(highest.load(), 0);
}

// A loop started inside a block, or from a second thread while the pool is
// busy, runs serially on its caller, with the same blocks.
TEST(ThreadPool, NestedAndConcurrentLoopsRunSeriallyOnTheirCaller) {
  swirl::parallel::set_thread_count(3);
  std::vector<std::atomic<int>> hits(40 * 40);
  for_blocks("outer", 40, 1, [&](std::size_t i, std::size_t, std::size_t) {
    const int me = swirl::parallel::thread_index();
    for_blocks("inner", 40, 1, [&](std::size_t j, std::size_t, std::size_t) {
      EXPECT_EQ(swirl::parallel::thread_index(), me);
      ++hits[i * 40 + j];
    });
  });
  for (auto& h : hits) EXPECT_EQ(h.load(), 1);

  std::vector<double> values(200000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = 1.0 / double(i + 1);
  const auto sum = [&] {
    return reduce_blocks(
        "sum", values.size(), 101, 0.0,
        [&](std::size_t b, std::size_t e) {
          double s = 0;
          for (std::size_t i = b; i < e; ++i) s += values[i];
          return s;
        },
        [](double x, double y) { return x + y; });
  };
  const double reference = sum();
  std::vector<double> results(4 * 50);
  std::vector<std::thread> callers;
  for (int t = 0; t < 4; ++t)
    callers.emplace_back([&, t] {
      for (int k = 0; k < 50; ++k) results[std::size_t(t * 50 + k)] = sum();
    });
  for (auto& c : callers) c.join();
  for (double r : results) EXPECT_EQ(r, reference);
}

// Under a SerialScope a thread's loops run on it alone (the pool stays free
// for another thread's jobs), with the same results; the scope ends with it.
TEST(ThreadPool, ASerialScopeKeepsItsThreadsLoopsOffThePool) {
  swirl::parallel::set_thread_count(3);
  std::vector<double> values(100000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = 1.0 / double(i + 1);
  const auto sum = [&] {
    return reduce_blocks(
        "sum", values.size(), 97, 0.0,
        [&](std::size_t b, std::size_t e) {
          double s = 0;
          for (std::size_t i = b; i < e; ++i) s += values[i];
          std::this_thread::sleep_for(std::chrono::microseconds(20));
          return s;
        },
        [](double x, double y) { return x + y; });
  };
  const double pooled = sum();
  std::atomic<int> highest{0};
  double serial = 0;
  {
    swirl::parallel::SerialScope scope;
    {
      swirl::parallel::SerialScope nested;
    }
    EXPECT_TRUE(swirl::parallel::detail::ThreadPool::serial_here()) << "a nested scope restores the outer one";
    serial = sum();
    for_blocks("serial", 64, 1, [&](std::size_t, std::size_t, std::size_t) {
      highest = std::max(highest.load(), swirl::parallel::thread_index());
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    });
  }
  EXPECT_EQ(highest.load(), 0) << "a worker ran a block of a serial scope's loop";
  EXPECT_EQ(serial, pooled);
  EXPECT_FALSE(swirl::parallel::detail::ThreadPool::serial_here());
  for (int attempt = 0; attempt < 100 && highest.load() == 0; ++attempt)
    for_blocks("pooled again", 16, 1, [&](std::size_t, std::size_t, std::size_t) {
      highest = std::max(highest.load(), swirl::parallel::thread_index());
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
  EXPECT_GT(highest.load(), 0) << "after the scope the pool takes part again";
}

}  // namespace
