// `swirl hash-stats`: the thesis's Table 5.2 for a scene's particles.
#pragma once

#include <cstdint>

#include "swirl/scene/scene.hpp"
#include "swirl/spatial/hash_statistics.hpp"

namespace swirl::sim {

// Builds the scene (it needs [sph]), runs `steps` steps first if asked (the
// thesis measured a running simulation), then measures the hash table of the
// current positions with the scene's h and bucket count (sph.hash.buckets, or
// the default 1.6·N). Throws std::invalid_argument for a scene without [sph].
spatial::HashStatistics scene_hash_statistics(const scene::Scene& scene, std::uint64_t steps = 0);

}  // namespace swirl::sim
