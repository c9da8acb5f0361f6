// ThreadGovernor: chooses, step by step, how many of the allowed threads a run
// uses, from the step times it measures: a machine whose cores another
// process keeps busy does not drag the run below its one-thread speed.
//
// Why: every parallel pass ends in a barrier, and a step has a few dozen
// passes. When another process holds one of the cores, the thread that shares
// it is descheduled for whole time slices and every barrier waits for it:
// measured on a 2-core machine, 2 threads fell from ~200 to ~78 steps/s while
// 1 thread kept ~112 (docs/performance/pipeline.md). Fewer threads are then
// faster, and only measuring tells when.
//
// How: the governor exploits a count for a while, then probes a neighbouring
// count (half, or double up to the maximum) for a few steps, and moves when
// the probe's median step time beats the median of the steps just before it
// by a margin. A probe that loses doubles the wait before the next one (up to
// a cap), so a quiet machine spends a vanishing share of its steps probing;
// a move resets the wait. Medians make one slow step (a frame written, a
// re-sort of the order) irrelevant.
//
// Determinism: swirl's results do not depend on the thread count (fixed
// blocks, block-order reductions), so this changes speed only, never a bit
// of the results. Not thread-safe: the run loop calls it between steps.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace swirl::parallel {

class ThreadGovernor {
 public:
  struct Settings {
    std::size_t window = 7;          // steps per median (a probe's length)
    std::uint64_t first_wait = 64;   // steps before the first probe, and after a move
    std::uint64_t max_wait = 1024;   // the longest wait between probes
    double margin = 0.05;            // a probe must be this much faster (5 %) to move
  };

  explicit ThreadGovernor(int max_threads) : ThreadGovernor(max_threads, Settings{}) {}
  ThreadGovernor(int max_threads, Settings settings)
      : max_(max_threads), current_(max_threads), settings_(settings), wait_(settings.first_wait) {
    if (max_threads < 1) throw std::invalid_argument("thread governor: at least one thread");
    if (settings.window < 1) throw std::invalid_argument("thread governor: a window of at least one step");
  }

  // The thread count for the next step.
  int threads() const { return probing_ ? probe_ : current_; }

  // The step just taken (at threads()) took `seconds`.
  void record(double seconds) {
    ++steps_;
    if (threads() < max_) ++steps_below_max_;
    if (max_ == 1) return;
    if (probing_) {
      probe_times_.push_back(seconds);
      if (probe_times_.size() == settings_.window) finish_probe();
      return;
    }
    recent_.push_back(seconds);
    if (recent_.size() > settings_.window) recent_.erase(recent_.begin());
    if (++since_probe_ >= wait_ && recent_.size() == settings_.window) start_probe();
  }

  int max_threads() const { return max_; }
  std::uint64_t steps() const { return steps_; }
  // Steps taken with fewer threads than allowed (probes included).
  std::uint64_t steps_below_max() const { return steps_below_max_; }
  std::uint64_t moves() const { return moves_; }

 private:
  static double median(std::vector<double> v) {
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
  }

  void start_probe() {
    // Alternate downwards and upwards where both exist.
    const int down = std::max(1, current_ / 2), up = std::min(max_, current_ * 2);
    if (down == current_) probe_ = up;
    else if (up == current_) probe_ = down;
    else probe_ = (probes_ % 2 == 0) ? down : up;
    ++probes_;
    probing_ = true;
    probe_times_.clear();
  }

  void finish_probe() {
    probing_ = false;
    since_probe_ = 0;
    if (median(probe_times_) < (1 - settings_.margin) * median(recent_)) {
      current_ = probe_;
      ++moves_;
      wait_ = settings_.first_wait;
      recent_ = probe_times_;  // the new count's own recent steps
    } else {
      wait_ = std::min(settings_.max_wait, 2 * wait_);
    }
  }

  int max_;
  int current_;
  Settings settings_;
  std::uint64_t wait_;
  std::uint64_t since_probe_ = 0;
  bool probing_ = false;
  int probe_ = 0;
  std::uint64_t probes_ = 0;
  std::vector<double> recent_, probe_times_;
  std::uint64_t steps_ = 0, steps_below_max_ = 0, moves_ = 0;
};

}  // namespace swirl::parallel
