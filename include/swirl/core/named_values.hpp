// NamedValues: a small list of (name, value) pairs — the state a solver, a
// stepper or an observer keeps across a checkpoint, and the figures it reports
// in a run's summary. Names are dotted by owner ("sph.neighbour_sum",
// "frames.written"), so owners never collide.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace swirl {

using NamedValues = std::vector<std::pair<std::string, double>>;

// The value called `name`, if present.
inline std::optional<double> find_value(const NamedValues& values, std::string_view name) {
  for (const auto& [n, v] : values)
    if (n == name) return v;
  return std::nullopt;
}

}  // namespace swirl
