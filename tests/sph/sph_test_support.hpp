// Fluid set-ups shared by the SPH tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>

#include "swirl/core/box.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/random.hpp"
#include "swirl/force/uniform_gravity.hpp"
#include "swirl/parallel/for_blocks.hpp"
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

// A lattice stretched along z so that its density falls linearly with height
// (ρ ≈ ρ0·(1 − δ·z)), frozen: the SPH pressure force of interior particles
// against the analytic −(1/ρ)·dp/dz = c²·δ. Eq. 2.8 gives half of it (see
// sph_fluid.hpp), the consistent form all of it.
template <class Real>
inline double pressure_acceleration_ratio(sph::PressureForm form) {
  const double s = 0.01, h = 2.1 * s, rho0 = 1000, c = 20, side = 0.2, delta = 9.81 / (c * c);
  auto p = swirl::testing::lattice_fluid<Real>({0, 0, 0}, {side, side, side}, s, h, rho0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double z = p.position.z[i];
    p.position.z[i] = Real(z + delta * z * z / 2);  // local stretch 1 + δ·z
  }
  sph::SphParameters params;
  params.smoothing_length = h;
  params.rest_density = rho0;
  params.sound_speed = c;
  params.viscosity = 0;
  params.pressure_form = form;
  sph::SphFluid<Real> fluid(params);
  swirl::evaluate_alone(fluid, p, 128);
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    bool deep = true;
    for (int a = 0; a < 3; ++a) deep = deep && p.position[a][i] > 2.5 * h && p.position[a][i] < side - 2.5 * h;
    if (!deep) continue;
    sum += p.acceleration.z[i] / (c * c * delta * rho0 / p.density[i]);
    ++n;
  }
  return sum / n;
}

// Whole-fluid sums that compare two runs of the same fluid (the hash path
// against the grid): energies, momentum and the density error.
struct FluidDiagnostics {
  double kinetic_energy = 0;      // Σ ½ m |v|², J
  double potential_energy = 0;    // Σ −m g·x, J (zero at the origin)
  Vec3d momentum{};               // Σ m v, kg·m/s
  double mean_density_error = 0;  // mean |ρ − ρ0| / ρ0
  double max_density_error = 0;   // max |ρ − ρ0| / ρ0
};

// Sums in block order: the same bits for any thread count.
template <class Real>
FluidDiagnostics fluid_diagnostics(const ParticleSet<Real>& p, const Vec3d& gravity, double rest_density,
                                   std::size_t block_size) {
  using Partial = std::array<double, 7>;  // K, U, px, py, pz, Σ error, max error
  const Partial total = parallel::reduce_blocks(
      "fluid_diagnostics", p.size(), block_size, Partial{},
      [&](std::size_t b, std::size_t e) {
        Partial s{};
        for (std::size_t i = b; i < e; ++i) {
          const double m = p.mass[i];
          double v2 = 0;
          for (int a = 0; a < 3; ++a) {
            const double v = p.velocity[a][i];
            v2 += v * v;
            s[2 + a] += m * v;
            s[1] -= m * gravity[a] * double(p.position[a][i]);
          }
          s[0] += 0.5 * m * v2;
          const double error = std::abs(double(p.density[i]) - rest_density) / rest_density;
          s[5] += error;
          s[6] = std::max(s[6], error);
        }
        return s;
      },
      [](Partial a, const Partial& b) {
        for (int k = 0; k < 6; ++k) a[k] += b[k];
        a[6] = std::max(a[6], b[6]);
        return a;
      });
  FluidDiagnostics d;
  d.kinetic_energy = total[0];
  d.potential_energy = total[1];
  d.momentum = {total[2], total[3], total[4]};
  d.mean_density_error = p.empty() ? 0.0 : total[5] / double(p.size());
  d.max_density_error = total[6];
  return d;
}

}  // namespace swirl::testing
