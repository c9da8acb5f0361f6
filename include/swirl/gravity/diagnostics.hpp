// Conserved quantities and equilibrium measures of a self-gravitating system
// (G = 1), the columns of a gravity run's diagnostics:
//
//   K = ½ Σ m_i |v_i|²,  W = ½ Σ m_i φ_i (φ from the gravity walk: the
//   "potential" field GravityForce writes), E = K + W,  P = Σ m_i v_i,
//   L = Σ m_i x_i × v_i,  virial ratio 2K/|W| (1 in equilibrium).
//
// Sums are accumulated in double per block and folded in block order
// (parallel::reduce_blocks): bit-identical for any thread count.
#pragma once

#include <cstddef>

#include "swirl/core/particle_set.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/dist/block_fold.hpp"

namespace swirl::gravity {

struct Diagnostics {
  double mass = 0;
  double kinetic = 0;
  double potential = 0;
  double total = 0;
  double virial_ratio = 0;  // 2K/|W|; 0 if W = 0
  Vec3d momentum{};
  Vec3d angular_momentum{};  // about the origin
  Vec3d centre_of_mass{};
};

// Throws std::invalid_argument if p has no "potential" field (evaluate GravityForce first).
template <class Real>
Diagnostics diagnose(const ParticleSet<Real>& p, std::size_t block_size = 1024);

// W = ½ Σ m_i φ_i from the "potential" field (same exception as diagnose()),
// and the virial ratio 2K/|W| (0 if W = 0), over this rank's particles in the
// one-rank block order (dist/block_fold.hpp: collective on ranks, the same
// bits on any rank count): GravityForce's diagnostics.csv columns.
template <class Real>
double potential_energy(const ParticleSet<Real>& p, const dist::BlockFold& fold);
template <class Real>
double virial_ratio(const ParticleSet<Real>& p, const dist::BlockFold& fold);
// W of the whole set on one rank.
template <class Real>
double potential_energy(const ParticleSet<Real>& p, std::size_t block_size = 1024) {
  return potential_energy(p, dist::BlockFold::one_rank(block_size));
}

extern template Diagnostics diagnose<float>(const ParticleSet<float>&, std::size_t);
extern template Diagnostics diagnose<double>(const ParticleSet<double>&, std::size_t);
extern template double potential_energy<float>(const ParticleSet<float>&, const dist::BlockFold&);
extern template double potential_energy<double>(const ParticleSet<double>&, const dist::BlockFold&);
extern template double virial_ratio<float>(const ParticleSet<float>&, const dist::BlockFold&);
extern template double virial_ratio<double>(const ParticleSet<double>&, const dist::BlockFold&);

}  // namespace swirl::gravity
