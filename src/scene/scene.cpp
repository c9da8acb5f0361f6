#include <algorithm>
#include <cmath>
#include <limits>

#include "swirl/scene/scene.hpp"

namespace swirl::scene {

std::uint64_t Scene::total_steps() const {
  if (steps) return *steps;
  if (!end_time) return 0;
  const double ratio = *end_time / dt;
  if (!(ratio > 0)) return 0;
  // end_time is usually meant as a whole number of steps, but end_time / dt
  // rounds either way (0.3 / 0.1 = 2.9999999999999996, 0.9 / 0.03 =
  // 30.000000000000004); a plain ceil would add a needless step for the latter.
  const double n = std::max(1.0, std::ceil(ratio - 1e-9));
  return n < 0x1p64 ? static_cast<std::uint64_t>(n) : std::numeric_limits<std::uint64_t>::max();
}

}  // namespace swirl::scene
