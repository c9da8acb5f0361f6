// The one wrapper through which every per-particle pass runs in parallel.
//
// It is the thesis's workpool (section 4, Algorithm 2) on today's cores: the
// index range is cut into fixed work blocks of `block_size` items, and the
// threads of swirl's pool (thread_pool.hpp) take blocks dynamically. Block boundaries depend only on n and
// block_size, never on the thread count, so a pass whose blocks write disjoint
// data (gather, not scatter) gives bit-identical results on any thread count;
// reduce_blocks() keeps that promise for reductions by combining per-block
// partial results in block order.
//
// Blocks go to threads in one of two ways, neither of which changes a result:
// for_blocks/reduce_blocks are the workpool (a thread takes the next free
// block: for irregular work such as tree walks); the _pinned variants give
// thread t the same contiguous run of blocks on every call, so a particle is
// handled by the same core in every pass and, while the particle order is
// stable, in every step: its data stay in that core's caches. The uniform
// per-particle passes of the SPH grid and the integrator use them (measured in
// docs/performance/sph-grid.md). A thread that has finished its own run then
// takes the unstarted blocks of the others' runs, so a thread that the
// operating system deschedules (another process busy on its core) delays the
// pass by at most the block it holds, not by its whole run, and the caller
// never waits for a thread that has not started: OpenMP's static schedule, and
// then its end-of-region barrier, collapsed below one thread's speed on a
// loaded 2-core machine.
//
// An exception thrown inside a block is caught (it must not escape a pool
// thread), the loop finishes, and the first one is rethrown with the kernel's
// name prepended.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <omp.h>

#include "swirl/parallel/thread_pool.hpp"

namespace swirl::parallel {

// The most threads swirl starts. Every thread costs a stack, and tens of
// thousands exhaust the memory for them. More than 4 threads per hardware
// thread never speed a pass up; 64 at least still lets a small machine test
// that results do not depend on the thread count.
inline int max_thread_count() { return std::clamp(4 * omp_get_num_procs(), 64, 1024); }

// The pool that runs every parallel pass, started on first use with OpenMP's
// default thread count (OMP_NUM_THREADS, else one per processor).
inline detail::ThreadPool& pool() {
  static detail::ThreadPool& threads = []() -> detail::ThreadPool& {
    auto& p = detail::ThreadPool::instance();
    p.resize(std::min(omp_get_max_threads(), max_thread_count()));
    return p;
  }();
  return threads;
}

// Threads the next parallel loop will use.
inline int thread_count() { return pool().size(); }

// This thread's index in the running loop: 0 for the caller, 1..thread_count()-1
// for the pool's workers (a per-thread scratch buffer's index).
inline int thread_index() { return detail::ThreadPool::thread_index(); }

// Sets the threads used by later loops; 1 <= n <= max_thread_count(), else
// std::invalid_argument.
inline void set_thread_count(int n) {
  if (n < 1) throw std::invalid_argument("thread count must be at least 1");
  if (n > max_thread_count())
    throw std::invalid_argument("thread count " + std::to_string(n) + " is more than the " +
                                std::to_string(max_thread_count()) + " threads swirl starts on this machine");
  omp_set_num_threads(n);
  pool().resize(n);
}

// OMP_NUM_THREADS (or anything else that set OpenMP's default) above
// max_thread_count() is lowered to it, for the same reason; returns a warning
// to show the user then, or an empty string.
inline std::string clamp_default_thread_count() {
  const int asked = omp_get_max_threads(), max = max_thread_count();
  if (asked <= max) return {};
  omp_set_num_threads(max);
  pool().resize(max);
  return "OpenMP was asked for " + std::to_string(asked) + " threads (OMP_NUM_THREADS); using " +
         std::to_string(max) + ", the most swirl starts on this machine";
}

// While alive, the parallel loops of the thread that made it run on that
// thread alone, never on the pool. For a thread working beside the
// simulation (swirl view's mesher): its loops would otherwise take the pool
// whenever the simulation's thread is between two passes, and a pass the
// simulation submits meanwhile runs serially on its caller (one job at a
// time), so the solver would lose its workers for the length of the other
// thread's loop. The blocks, and so the results, are the same either way.
// Scopes nest; each restores what it found.
class SerialScope {
 public:
  SerialScope() : before_(detail::ThreadPool::serial_here()) { detail::ThreadPool::set_serial_here(true); }
  ~SerialScope() { detail::ThreadPool::set_serial_here(before_); }
  SerialScope(const SerialScope&) = delete;
  SerialScope& operator=(const SerialScope&) = delete;

 private:
  bool before_;
};

// Number of blocks of block_size items covering n items.
constexpr std::size_t block_count(std::size_t n, std::size_t block_size) {
  return block_size == 0 ? 0 : (n + block_size - 1) / block_size;
}

namespace detail {
class FirstError {
 public:
  void capture() noexcept {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = std::current_exception();
  }
  void rethrow(std::string_view kernel) const {
    if (!error_) return;
    try {
      std::rethrow_exception(error_);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string(kernel) + ": " + e.what());
    }
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
};
}  // namespace detail

namespace detail {
enum class Schedule { Dynamic, Pinned };

template <class Body>
void run_blocks(Schedule schedule, std::string_view kernel, std::size_t n, std::size_t block_size, Body&& body) {
  if (block_size == 0) throw std::invalid_argument(std::string(kernel) + ": block size must be at least 1");
  const auto blocks = static_cast<std::int64_t>(block_count(n, block_size));
  FirstError error;
  const auto run = [&](std::int64_t b) {
    try {
      const std::size_t begin = static_cast<std::size_t>(b) * block_size;
      body(begin, std::min(n, begin + block_size), static_cast<std::size_t>(b));
    } catch (...) {
      error.capture();
    }
  };
  // Pinned: run t of the job is thread t's, the same blocks on every call.
  auto& threads = pool();
  const std::int64_t runs = schedule == Schedule::Pinned ? std::min<std::int64_t>(threads.size(), blocks) : 1;
  threads.run(blocks, runs, [](void* context, std::int64_t b) { (*static_cast<decltype(run)*>(context))(b); },
              const_cast<void*>(static_cast<const void*>(&run)));
  error.rethrow(kernel);
}

template <class T, class BlockResult, class Combine>
T reduce(Schedule schedule, std::string_view kernel, std::size_t n, std::size_t block_size, T init,
         BlockResult&& block_result, Combine&& combine) {
  // One slot per block, wrapped so that T = bool does not become the packed
  // std::vector<bool>, whose neighbouring bits two threads would race on.
  struct Slot {
    T value;
  };
  std::vector<Slot> partial(block_count(n, block_size), Slot{init});
  run_blocks(schedule, kernel, n, block_size, [&](std::size_t begin, std::size_t end, std::size_t b) {
    partial[b].value = block_result(begin, end);
  });
  T total = init;
  for (const Slot& p : partial) total = combine(total, p.value);
  return total;
}
}  // namespace detail

// Calls body(begin, end, block) for every block [begin, end) of [0, n), in
// parallel, blocks to threads as a workpool. body must only write data owned
// by its own block.
template <class Body>
void for_blocks(std::string_view kernel, std::size_t n, std::size_t block_size, Body&& body) {
  detail::run_blocks(detail::Schedule::Dynamic, kernel, n, block_size, std::forward<Body>(body));
}

// for_blocks with every block pinned to the same thread on every call.
template <class Body>
void for_blocks_pinned(std::string_view kernel, std::size_t n, std::size_t block_size, Body&& body) {
  detail::run_blocks(detail::Schedule::Pinned, kernel, n, block_size, std::forward<Body>(body));
}

// Computes partial = block_result(begin, end) for every block in parallel, then
// folds them in block order: combine(combine(init, p0), p1)... Deterministic
// for any thread count, also for floating-point sums.
template <class T, class BlockResult, class Combine>
T reduce_blocks(std::string_view kernel, std::size_t n, std::size_t block_size, T init, BlockResult&& block_result,
                Combine&& combine) {
  return detail::reduce(detail::Schedule::Dynamic, kernel, n, block_size, std::move(init),
                        std::forward<BlockResult>(block_result), std::forward<Combine>(combine));
}

// reduce_blocks with every block pinned to the same thread on every call.
template <class T, class BlockResult, class Combine>
T reduce_blocks_pinned(std::string_view kernel, std::size_t n, std::size_t block_size, T init,
                       BlockResult&& block_result, Combine&& combine) {
  return detail::reduce(detail::Schedule::Pinned, kernel, n, block_size, std::move(init),
                        std::forward<BlockResult>(block_result), std::forward<Combine>(combine));
}

}  // namespace swirl::parallel
