// The slow twin of every neighbour search: all pairs, O(N²), one thread.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/spatial/distance.hpp"

namespace swirl::spatial {

// Every ordered pair (i, j), i ≠ j, with |x_i − x_j|² < h², sorted by (i, j).
template <class Real>
std::vector<std::pair<std::uint32_t, std::uint32_t>> brute_force_pairs(const ParticleSet<Real>& p, Real h) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  const Real h2 = h * h;
  for (std::uint32_t i = 0; i < p.size(); ++i)
    for (std::uint32_t j = 0; j < p.size(); ++j)
      if (i != j && within(distance2(p.position.x[i], p.position.y[i], p.position.z[i], p.position.x[j],
                                     p.position.y[j], p.position.z[j]),
                           h2))
        pairs.emplace_back(i, j);
  return pairs;
}

}  // namespace swirl::spatial
