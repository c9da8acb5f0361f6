#include "swirl/sim/hash_stats.hpp"

#include <stdexcept>

#include "swirl/sim/build.hpp"

namespace swirl::sim {
namespace {

template <class Real>
spatial::HashStatistics measure(const scene::Scene& scene, std::uint64_t steps) {
  auto sim = build_simulation<Real>(scene);
  if (steps > 0) {
    sim.start();
    for (std::uint64_t s = 0; s < steps; ++s) sim.step();
  }
  const auto& p = sim.particles();
  const auto& params = *scene.sph;
  const std::uint32_t buckets = params.buckets ? params.buckets : sph::default_bucket_count(p.size());
  return spatial::hash_statistics(p, Real(params.smoothing_length), buckets, scene.block_size);
}

}  // namespace

spatial::HashStatistics scene_hash_statistics(const scene::Scene& scene, std::uint64_t steps) {
  if (!scene.sph) throw std::invalid_argument(scene.file + ": hash-stats needs an SPH scene (an [sph] section)");
  return scene.precision == scene::Precision::Float ? measure<float>(scene, steps) : measure<double>(scene, steps);
}

}  // namespace swirl::sim
