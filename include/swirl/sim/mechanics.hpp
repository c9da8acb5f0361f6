#pragma once
// The mechanical totals of a particle set and the solvers' diagnostic values:
// what the run's diagnostics.csv logs and the live view's statuses plot, from
// one place so that both report the same numbers.
//
// mechanics(): K = ½ Σ m|v|² (energy units of the scene: m·L²/T²),
// P = Σ m v, L = Σ m x × v (about the origin). Sums are in double per block,
// folded in block order, so they have the same bits for any thread count.
// Boundary particles are left out: their "mass" is a volume weight ψ, and a
// moving obstacle's prescribed velocity is not the fluid's.
//
// potential_energy(): the solvers' potential energies summed (the log's
// potential_energy column).
// diagnostic_values(): each solver's columns, then the stepper's, as name and
// value, in the order of diagnostics.csv's header.
#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "swirl/core/particle_kind.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::sim {

struct Mechanics {
  double kinetic = 0;
  std::array<double, 3> momentum{}, angular{};
};

template <class Real>
Mechanics mechanics(const ParticleSet<Real>& p, std::size_t block_size) {
  using Partial = std::array<double, 7>;
  const std::size_t kinds = p.find_int_field(kKindField);
  const std::int32_t* kind = kinds == ParticleSet<Real>::npos ? nullptr : p.int_field(kinds).data();
  const Partial t = parallel::reduce_blocks(
      "mechanics", p.size(), block_size, Partial{},
      [&](std::size_t b, std::size_t e) {
        Partial s{};
        for (std::size_t i = b; i < e; ++i) {
          if (kind && is_boundary(kind[i])) continue;
          const double m = p.mass[i];
          const double x = p.position.x[i], y = p.position.y[i], z = p.position.z[i];
          const double vx = p.velocity.x[i], vy = p.velocity.y[i], vz = p.velocity.z[i];
          s[0] += 0.5 * m * (vx * vx + vy * vy + vz * vz);
          s[1] += m * vx, s[2] += m * vy, s[3] += m * vz;
          s[4] += m * (y * vz - z * vy), s[5] += m * (z * vx - x * vz), s[6] += m * (x * vy - y * vx);
        }
        return s;
      },
      [](Partial a, const Partial& b) {
        for (std::size_t k = 0; k < a.size(); ++k) a[k] += b[k];
        return a;
      });
  return {t[0], {t[1], t[2], t[3]}, {t[4], t[5], t[6]}};
}

template <class Real>
double potential_energy(const Simulation<Real>& sim, const ParticleSet<Real>& p, std::size_t block_size) {
  double potential = 0;
  for (const auto& s : sim.solvers()) potential += s->potential_energy(p, block_size);
  return potential;
}

// Names and values of the solvers' and the stepper's own diagnostics for the
// set `p` (the whole set: on ranks, the gathered one).
template <class Real>
std::vector<std::pair<std::string, double>> diagnostic_values(const Simulation<Real>& sim, const ParticleSet<Real>& p,
                                                              std::size_t block_size) {
  std::vector<std::string> names;
  std::vector<double> values;
  for (const auto& s : sim.solvers()) {
    for (auto& c : s->diagnostic_columns()) names.push_back(std::move(c));
    s->add_diagnostics(p, block_size, values);
  }
  for (auto& c : sim.stepper().diagnostic_columns()) names.push_back(std::move(c));
  sim.stepper().add_diagnostics(values);
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t k = 0; k < names.size() && k < values.size(); ++k) out.emplace_back(std::move(names[k]), values[k]);
  return out;
}

}  // namespace swirl::sim
