// Observer<Real>: the seam through which anything that watches a run enters
// the run loop — frame writers, the diagnostics log, checkpoints, progress,
// the guard's warnings, a renderer, a live viewer, a Python callback.
//
// The loop (sim/run.cpp) is:
//   start or resume the simulation;   every observer's on_start()
//   while the run goes on:            step (landing on the earliest next_time())
//                                     every observer's on_step()
//   unless interrupted or failed:     every observer's on_finish()
// in the order the observers were added. An observer decides itself when it
// acts (its trigger: every N steps, every T of simulated time, on request),
// keeps the state its trigger needs, and saves that state in checkpoints
// (save_state/load_state, names prefixed with its name), so a resumed run's
// observers act exactly where the uninterrupted run's would have.
//
// Observers only read the simulation, except where they say otherwise (a
// guard reporter takes the simulation's warning events).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string_view>

#include "swirl/core/named_values.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::sim {

template <class Real>
class Observer {
 public:
  virtual ~Observer() = default;
  virtual std::string_view name() const = 0;
  // The state the run starts from: after start() (resumed = false) or after a
  // checkpoint was read and load_state() called (resumed = true).
  virtual void on_start(Simulation<Real>& /*sim*/, bool /*resumed*/) {}
  // After every step.
  virtual void on_step(Simulation<Real>& /*sim*/) {}
  // Once, at the end of a run that reached its end (not interrupted, not failed).
  virtual void on_finish(Simulation<Real>& /*sim*/) {}
  // The next simulated time this observer acts at, if it acts at times:
  // adaptive steps are shortened to land on it exactly.
  virtual std::optional<double> next_time(const Simulation<Real>& /*sim*/) const { return std::nullopt; }
  virtual void save_state(NamedValues& /*out*/) const {}
  virtual void load_state(const NamedValues& /*values*/) {}
};

// When an observer that acts at times of an interval is due: action k (k ≥ 1)
// happens at the first step whose time is ≥ k·interval, where a slack of
// 1e-9·dt keeps a k·interval that lands on a step (up to rounding) on that
// step. After acting, the next k is the first multiple past the current time.
class IntervalSchedule {
 public:
  IntervalSchedule(double interval, double dt) : interval_(interval), slack_(1e-9 * dt) {}
  bool enabled() const { return interval_ > 0; }
  bool due(double time) const { return enabled() && time + slack_ >= static_cast<double>(next_) * interval_; }
  void acted(double time) { next_ = static_cast<std::uint64_t>(std::floor((time + slack_) / interval_)) + 1; }
  std::optional<double> next_time() const {
    if (!enabled()) return std::nullopt;
    return static_cast<double>(next_) * interval_;
  }
  std::uint64_t next_index() const { return next_; }
  void set_next_index(std::uint64_t k) { next_ = k; }

 private:
  double interval_;
  double slack_;
  std::uint64_t next_ = 1;
};

}  // namespace swirl::sim
