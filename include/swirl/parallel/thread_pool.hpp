// The threads behind every parallel pass: a pool whose caller waits only for
// blocks, never for threads.
//
// A job is a count of blocks cut into runs (one run for a workpool, one per
// thread for pinned blocks). Every thread, the caller included, takes the
// blocks of its own run first, then the unstarted blocks of the other runs.
// The caller returns as soon as every block has finished: a worker that the
// operating system has not scheduled yet (another process busy on its core) is
// simply not needed; its run is done by the others, and when it wakes it finds
// the job closed and touches nothing. An OpenMP region, by contrast, ends in a
// barrier that every thread of the team must reach, so one descheduled thread
// stalled every pass (docs/performance/pipeline.md measures both).
//
// Waiting threads spin for a short while (the next pass of a step usually
// follows within microseconds) and then sleep on a futex (std::atomic::wait).
// A sleeping caller leaves its core idle, so the kernel can move a worker that
// is queued behind another process onto it.
//
// Invariants: which thread runs a block never changes a result (blocks write
// disjoint data, see for_blocks.hpp); the job's state is read by a worker only
// after it has registered as active and found the job still open, and the
// caller closes the job and waits for the active count to drop to zero before it
// returns, so no thread touches a finished job's task. A job submitted from
// inside a job, or while another thread's job is running, runs serially on its
// caller, and so does every job of a thread that asked for it
// (set_serial_here: a thread beside the solver's). thread_index() is 0 on the caller (and on any thread outside the
// pool) and 1..size()-1 on the workers.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace swirl::parallel::detail {

inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// Spins while word == old for up to `spin`, then sleeps until it changes;
// returns the new value.
inline std::uint32_t wait_for_change(const std::atomic<std::uint32_t>& word, std::uint32_t old,
                                     std::chrono::nanoseconds spin) noexcept {
  std::uint32_t now = word.load(std::memory_order_acquire);
  if (now != old) return now;
  const auto until = std::chrono::steady_clock::now() + spin;
  for (unsigned i = 1;; ++i) {
    cpu_relax();
    now = word.load(std::memory_order_acquire);
    if (now != old) return now;
    if (i % 64 == 0 && std::chrono::steady_clock::now() >= until) break;
  }
  for (;;) {
    word.wait(old, std::memory_order_acquire);
    now = word.load(std::memory_order_acquire);
    if (now != old) return now;
  }
}

class ThreadPool {
 public:
  using Task = void (*)(void* context, std::int64_t block);

  static ThreadPool& instance() {
    static ThreadPool pool;
    return pool;
  }

  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  ~ThreadPool() { stop_workers(); }

  // Threads of a job, the caller included.
  int size() const noexcept { return size_.load(std::memory_order_relaxed); }

  // Starts or stops workers so that jobs use `threads` threads (≥ 1). Must not
  // be called from inside a job.
  void resize(int threads) {
    std::lock_guard lock(submit_);
    if (threads == size()) return;
    stop_workers();
    size_.store(threads, std::memory_order_relaxed);
    claimed_ = std::make_unique<Claimed[]>(static_cast<std::size_t>(threads));
    stop_.store(false, std::memory_order_relaxed);
    // A worker starts from the generation of its birth, so that a stop
    // published before it first runs is still a change it sees.
    const std::uint32_t born = generation_.load(std::memory_order_relaxed);
    for (int w = 1; w < threads; ++w) workers_.emplace_back([this, w, born] { worker_loop(w, born); });
  }

  static int thread_index() noexcept { return index_; }

  // While set, the jobs this thread submits run serially on it and leave the
  // pool to the others (parallel::SerialScope).
  static void set_serial_here(bool serial) noexcept { serial_here_ = serial; }
  static bool serial_here() noexcept { return serial_here_; }

  // Runs task(context, b) once for every b in [0, blocks), the blocks split into
  // `runs` contiguous runs (1 ≤ runs ≤ size()), run r first offered to thread r.
  // task must not throw.
  void run(std::int64_t blocks, std::int64_t runs, Task task, void* context) {
    if (blocks <= 0) return;
    const auto serially = [&] {
      for (std::int64_t b = 0; b < blocks; ++b) task(context, b);
    };
    // inside_ first: the caller of the running job holds submit_, and must not
    // try to lock it again.
    if (inside_ || serial_here_ || size() == 1 || blocks == 1) return serially();
    std::unique_lock lock(submit_, std::try_to_lock);
    if (!lock.owns_lock()) return serially();
    task_ = task;
    context_ = context;
    blocks_ = blocks;
    runs_ = std::clamp<std::int64_t>(runs, 1, size());
    for (std::int64_t r = 0; r < runs_; ++r) claimed_[static_cast<std::size_t>(r)].count.store(0, std::memory_order_relaxed);
    finished_.store(0, std::memory_order_relaxed);
    done_.store(0, std::memory_order_relaxed);
    const std::uint32_t open = generation_.load(std::memory_order_relaxed) + 1;  // odd: open
    generation_.store(open, std::memory_order_release);
    generation_.notify_all();

    inside_ = true;
    work(0);
    inside_ = false;
    wait_for_change(done_, 0, caller_spin_);
    generation_.store(open + 1, std::memory_order_seq_cst);  // even: closed
    while (active_.load(std::memory_order_seq_cst) != 0) std::this_thread::yield();
  }

  // Test hook: while held, workers ignore new jobs (as if never scheduled), so
  // a test can prove that a job completes without them.
  void hold_workers(bool held) noexcept { held_.store(held, std::memory_order_seq_cst); }

 private:
  struct alignas(64) Claimed {
    std::atomic<std::int64_t> count{0};
  };

  ThreadPool() {
    caller_spin_ = spin_from_env("SWIRL_POOL_CALLER_SPIN_US", 300);
    worker_spin_ = spin_from_env("SWIRL_POOL_WORKER_SPIN_US", 300);
  }

  static std::chrono::nanoseconds spin_from_env(const char* name, long microseconds) {
    if (const char* text = std::getenv(name)) microseconds = std::strtol(text, nullptr, 10);
    return std::chrono::microseconds(std::max(0L, microseconds));
  }

  // Runs blocks until none is left unclaimed. The blocks it ran are added to
  // finished_ once, when it runs out (one shared write per thread and job, not
  // per block), or before it steals from another run: the window between a
  // block's end and its count is a few loads, never a block.
  void work(std::int64_t self) noexcept {
    const std::int64_t runs = runs_, blocks = blocks_;
    std::int64_t ran = 0;
    auto publish = [&] {
      if (ran == 0) return;
      if (finished_.fetch_add(ran, std::memory_order_acq_rel) + ran == blocks) {
        done_.store(1, std::memory_order_release);
        done_.notify_one();
      }
      ran = 0;
    };
    for (std::int64_t k = 0; k < runs; ++k) {
      const std::int64_t r = (self + k) % runs;
      const std::int64_t first = blocks * r / runs, last = blocks * (r + 1) / runs;
      auto& counter = claimed_[static_cast<std::size_t>(r)].count;
      // A run already taken costs one load, not a fetch_add, to skip.
      while (first + counter.load(std::memory_order_relaxed) < last) {
        const std::int64_t b = first + counter.fetch_add(1, std::memory_order_relaxed);
        if (b >= last) break;
        task_(context_, b);
        ++ran;
      }
      publish();
    }
  }

  void worker_loop(int self, std::uint32_t seen) {
    index_ = self;
    for (;;) {
      seen = wait_for_change(generation_, seen, worker_spin_);
      if (stop_.load(std::memory_order_acquire)) return;
      if ((seen & 1u) == 0 || held_.load(std::memory_order_relaxed)) continue;
      active_.fetch_add(1, std::memory_order_seq_cst);
      if (generation_.load(std::memory_order_seq_cst) == seen) {
        inside_ = true;
        work(self);
        inside_ = false;
      }
      active_.fetch_sub(1, std::memory_order_seq_cst);
    }
  }

  void stop_workers() {
    stop_.store(true, std::memory_order_release);
    generation_.fetch_add(2, std::memory_order_release);  // keeps its parity: no job opens
    generation_.notify_all();
    for (auto& w : workers_) w.join();
    workers_.clear();
  }

  static inline thread_local int index_ = 0;
  static inline thread_local bool inside_ = false;
  static inline thread_local bool serial_here_ = false;

  std::mutex submit_;  // one job at a time; also guards resize
  std::vector<std::thread> workers_;
  std::atomic<int> size_{1};
  std::atomic<bool> stop_{false}, held_{false};
  std::chrono::nanoseconds caller_spin_{}, worker_spin_{};

  // The open job, written by its caller before the generation is published.
  Task task_ = nullptr;
  void* context_ = nullptr;
  std::int64_t blocks_ = 0, runs_ = 1;
  std::unique_ptr<Claimed[]> claimed_ = std::make_unique<Claimed[]>(1);

  alignas(64) std::atomic<std::uint32_t> generation_{0};  // odd while a job is open
  alignas(64) std::atomic<std::int64_t> finished_{0};
  alignas(64) std::atomic<std::uint32_t> done_{0};
  alignas(64) std::atomic<int> active_{0};
};

}  // namespace swirl::parallel::detail
