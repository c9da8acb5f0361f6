// Turning a scene's particle sources into particles.
#pragma once

#include <cstddef>

#include "swirl/core/particle_set.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// Number of particles the sources will make (without making them).
std::size_t count_particles(const Scene& scene);

// Makes the particles of every source, in source order, with ids 0..N-1 in that
// order, positions, velocities and masses set and every other field zero.
// Deterministic: the same scene gives the same particles on any machine.
template <class Real>
ParticleSet<Real> make_particles(const Scene& scene);

extern template ParticleSet<float> make_particles<float>(const Scene&);
extern template ParticleSet<double> make_particles<double>(const Scene&);

}  // namespace swirl::scene
