// Fluid set-ups shared by the SPH tests.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>

#include "swirl/core/box.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/random.hpp"
#include "swirl/force/uniform_gravity.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/lattice_mass.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace swirl::testing {

// Particles on a cubic lattice of spacing s in [lo, hi) whose centres pass
// `keep`, each of the mass that gives ρ0 inside, at rest.
template <class Real, class Keep>
ParticleSet<Real> lattice_fluid(Vec3d lo, Vec3d hi, double s, double h, double rho0, Keep keep) {
  const double m = sph::lattice_mass_for_density(s, h, rho0);
  ParticleSet<Real> p;
  std::size_t n = 0;
  for (double z = lo.z + s / 2; z < hi.z; z += s)
    for (double y = lo.y + s / 2; y < hi.y; y += s)
      for (double x = lo.x + s / 2; x < hi.x; x += s) {
        if (!keep(Vec3d{x, y, z})) continue;
        p.resize(n + 1);
        p.position.set(n, Vec3d{x, y, z}.cast<Real>());
        p.mass[n] = Real(m);
        p.id[n] = n;
        ++n;
      }
  return p;
}

template <class Real>
ParticleSet<Real> lattice_fluid(Vec3d lo, Vec3d hi, double s, double h, double rho0) {
  return lattice_fluid<Real>(lo, hi, s, h, rho0, [](const Vec3d&) { return true; });
}

}  // namespace swirl::testing
