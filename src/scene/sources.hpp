// Internal to the scene module: particle counts, shared by validation (which
// must refuse huge scenes before anything allocates) and by make_particles.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "swirl/scene/scene.hpp"

namespace swirl::scene::detail {

// The most particles a scene may make: 2^31.
inline constexpr std::uint64_t kMaxParticles = std::uint64_t{1} << 31;

// Stands for "too many to count" in the saturating counts below.
inline constexpr std::uint64_t kSaturated = std::numeric_limits<std::uint64_t>::max();

// Lattice points along x, y and z: floor(extent / spacing) each, with a relative
// tolerance of 1e-12 so that 0.3 / 0.1 counts as 3. kSaturated when not finite or
// beyond 2^53.
std::array<std::uint64_t, 3> lattice_counts(const LatticeSource& source);

// Particles one source makes, saturating at kSaturated.
std::uint64_t source_count(const ParticleSource& source);

// a + b and a * b, saturating at kSaturated.
constexpr std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) { return a > kSaturated - b ? kSaturated : a + b; }
constexpr std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) {
  return a != 0 && b > kSaturated / a ? kSaturated : a * b;
}

}  // namespace swirl::scene::detail
