// Direct summation: the exact O(N²) reference every tree result is tested against.
//
// For every particle i (j ≠ i, G = 1, Plummer softening ε ≥ 0):
//   a_i = Σ_j m_j (x_j − x_i) / (|r|² + ε²)^{3/2},   φ_i = −Σ_j m_j / sqrt(|r|² + ε²)
// Parallel over blocks of i (parallel::for_blocks); each i's sum runs over j in
// index order, so the result is bit-identical for any thread count.
#pragma once

#include <cstddef>

#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/field.hpp"

namespace swirl::gravity {

// Overwrites out (resized to p.size()) with the direct-sum field of p.
template <class Real>
void direct_sum(const ParticleSet<Real>& p, Real softening, std::size_t block_size, GravityField<Real>& out);

extern template void direct_sum<float>(const ParticleSet<float>&, float, std::size_t, GravityField<float>&);
extern template void direct_sum<double>(const ParticleSet<double>&, double, std::size_t, GravityField<double>&);

}  // namespace swirl::gravity
