// Whole-fluid diagnostics for SPH runs, one row per output time.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "swirl/core/particle_set.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::sph {

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

}  // namespace swirl::sph
