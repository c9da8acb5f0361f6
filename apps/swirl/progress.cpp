#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "cli.hpp"

namespace swirl::cli {

ProgressDisplay::ProgressDisplay(std::FILE* out) : out_(out), terminal_(::isatty(::fileno(out)) == 1) {}

void ProgressDisplay::update(const sim::RunProgress& p) {
  const bool done = p.step >= p.total_steps;
  // A terminal is redrawn ten times a second; a log gets a line every 5 s.
  const double every = terminal_ ? 0.1 : 5.0;
  if (!done && p.wall_seconds - last_shown_ < every) return;
  last_shown_ = p.wall_seconds;

  // Never past 100 %, and the rate and ETA of this invocation's steps (a
  // resumed run starts at its checkpoint's step).
  const double fraction =
      p.total_steps ? std::min(1.0, static_cast<double>(p.step) / static_cast<double>(p.total_steps)) : 1.0;
  const std::uint64_t taken = p.step - std::min(p.first_step, p.step), left = p.total_steps - std::min(p.step, p.total_steps);
  const double rate = p.wall_seconds > 0 ? static_cast<double>(taken) / p.wall_seconds : 0.0;
  const double eta = rate > 0 ? static_cast<double>(left) / rate : 0.0;
  const std::string stats = fmt::format("step {}/{}  t = {:.4g}{}{}  {:.1f} steps/s  ETA {:.0f} s", p.step, p.total_steps,
                                        p.sim_time, p.time_unit.empty() ? "" : " ", p.time_unit, rate, std::ceil(eta));
  if (terminal_) {
    constexpr int width = 30;
    const int filled = std::clamp(static_cast<int>(fraction * width), 0, width);
    fmt::print(out_, "\r[{}{}] {:3.0f}%  {}\x1b[K", std::string(static_cast<std::size_t>(filled), '#'),
               std::string(static_cast<std::size_t>(width - filled), '.'), 100 * fraction, stats);
    drawn_ = true;
  } else {
    fmt::print(out_, "progress {:3.0f}%  {}\n", 100 * fraction, stats);
  }
  std::fflush(out_);
}

void ProgressDisplay::finish() {
  if (terminal_ && drawn_) fmt::print(out_, "\n");
  drawn_ = false;
}

}  // namespace swirl::cli
