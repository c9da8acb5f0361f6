#pragma once
// The mechanical totals of a particle set and the solvers' diagnostic values:
// what the run's diagnostics.csv logs and the live view's statuses plot, from
// one place so that both report the same numbers.
//
// mechanics(): K = ½ Σ m|v|² (energy units of the scene: m·L²/T²),
// P = Σ m v, L = Σ m x × v (about the origin). Sums are in double per block,
// folded in block order, so they have the same bits for any thread count; on
// ranks each rank passes its own particles and where they sit in the
// one-rank order (dist::BlockFold), and every rank gets the one-rank bits.
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
#include "swirl/dist/block_fold.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::sim {

struct Mechanics {
  double kinetic = 0;
  std::array<double, 3> momentum{}, angular{};
};

// Collective on ranks (fold.ranks), like every function below with a fold.
template <class Real>
Mechanics mechanics(const ParticleSet<Real>& p, const dist::BlockFold& fold) {
  using dist::FoldOp;
  const std::size_t kinds = p.find_int_field(kKindField);
  const std::int32_t* kind = kinds == ParticleSet<Real>::npos ? nullptr : p.int_field(kinds).data();
  constexpr FoldOp sum = FoldOp::Sum;
  const auto t = fold("mechanics", p.size(), std::array{sum, sum, sum, sum, sum, sum, sum},
                      [&](std::size_t i, std::array<double, 7>& s) {
                        if (kind && is_boundary(kind[i])) return false;
                        const double m = p.mass[i];
                        const double x = p.position.x[i], y = p.position.y[i], z = p.position.z[i];
                        const double vx = p.velocity.x[i], vy = p.velocity.y[i], vz = p.velocity.z[i];
                        s[0] = 0.5 * m * (vx * vx + vy * vy + vz * vz);
                        s[1] = m * vx, s[2] = m * vy, s[3] = m * vz;
                        s[4] = m * (y * vz - z * vy), s[5] = m * (z * vx - x * vz), s[6] = m * (x * vy - y * vx);
                        return true;
                      });
  return {t[0], {t[1], t[2], t[3]}, {t[4], t[5], t[6]}};
}

template <class Real>
double potential_energy(const Simulation<Real>& sim, const ParticleSet<Real>& p, const dist::BlockFold& fold) {
  double potential = 0;
  for (const auto& s : sim.solvers()) potential += s->potential_energy(p, fold);
  return potential;
}

// Names and values of the solvers' and the stepper's own diagnostics for the
// set `p` (this rank's particles, where fold says).
template <class Real>
std::vector<std::pair<std::string, double>> diagnostic_values(const Simulation<Real>& sim, const ParticleSet<Real>& p,
                                                              const dist::BlockFold& fold) {
  std::vector<std::string> names;
  std::vector<double> values;
  for (const auto& s : sim.solvers()) {
    for (auto& c : s->diagnostic_columns()) names.push_back(std::move(c));
    s->add_diagnostics(p, fold, values);
  }
  for (auto& c : sim.stepper().diagnostic_columns()) names.push_back(std::move(c));
  sim.stepper().add_diagnostics(values);
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t k = 0; k < names.size() && k < values.size(); ++k) out.emplace_back(std::move(names[k]), values[k]);
  return out;
}

// The same for the whole set on one rank (the live view, the Python module).
template <class Real>
Mechanics mechanics(const ParticleSet<Real>& p, std::size_t block_size) {
  return mechanics(p, dist::BlockFold::one_rank(block_size));
}
template <class Real>
double potential_energy(const Simulation<Real>& sim, const ParticleSet<Real>& p, std::size_t block_size) {
  return potential_energy(sim, p, dist::BlockFold::one_rank(block_size));
}
template <class Real>
std::vector<std::pair<std::string, double>> diagnostic_values(const Simulation<Real>& sim, const ParticleSet<Real>& p,
                                                              std::size_t block_size) {
  return diagnostic_values(sim, p, dist::BlockFold::one_rank(block_size));
}

}  // namespace swirl::sim
