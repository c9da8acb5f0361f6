// Wall-clock time per named phase of a run ("forces", "integrate", "output",
// ...), in seconds, in the order the phases were first used. Used for the run
// summary; not thread-safe: phases are timed around whole parallel passes.
#pragma once

#include <chrono>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace swirl {

class PhaseTimers {
 public:
  // Adds `seconds` to the phase `name`, creating it if new.
  void add(std::string_view name, double seconds) {
    for (auto& [n, s] : phases_) {
      if (n == name) { s += seconds; return; }
    }
    phases_.emplace_back(std::string(name), seconds);
  }
  // Seconds spent in `name` so far (0 if never used).
  double seconds(std::string_view name) const {
    for (const auto& [n, s] : phases_) if (n == name) return s;
    return 0.0;
  }
  const std::vector<std::pair<std::string, double>>& phases() const { return phases_; }

 private:
  std::vector<std::pair<std::string, double>> phases_;
};

// Times its own lifetime into one phase of a PhaseTimers.
class ScopedPhase {
 public:
  ScopedPhase(PhaseTimers& timers, std::string_view name)
      : timers_(timers), name_(name), start_(std::chrono::steady_clock::now()) {}
  ScopedPhase(const ScopedPhase&) = delete;
  ScopedPhase& operator=(const ScopedPhase&) = delete;
  ~ScopedPhase() {
    timers_.add(name_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }

 private:
  PhaseTimers& timers_;
  std::string_view name_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace swirl
