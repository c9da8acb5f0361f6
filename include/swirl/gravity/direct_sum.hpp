// Direct summation: the exact O(N²) reference every tree result is tested against.
//
// For every particle i (j ≠ i, G = 1, Plummer softening ε ≥ 0):
//   a_i = Σ_j m_j (x_j − x_i) / (|r|² + ε²)^{3/2},   φ_i = −Σ_j m_j / sqrt(|r|² + ε²)
// Parallel over blocks of i (parallel::for_blocks); each i's sum runs over j in
// index order, so the result is bit-identical for any thread count. With an
// active set only its particles' entries are computed (the others are left as
// they were); each is the same sum as in the full evaluation, bit for bit.
#pragma once

#include <cstddef>

#include "swirl/core/active_set.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/field.hpp"

namespace swirl::gravity {

// Overwrites out (resized to p.size()) with the direct-sum field of p (of its active particles).
template <class Real>
void direct_sum(const ParticleSet<Real>& p, Real softening, std::size_t block_size, GravityField<Real>& out,
                const ActiveSet& active = {});

extern template void direct_sum<float>(const ParticleSet<float>&, float, std::size_t, GravityField<float>&,
                                       const ActiveSet&);
extern template void direct_sum<double>(const ParticleSet<double>&, double, std::size_t, GravityField<double>&,
                                        const ActiveSet&);

}  // namespace swirl::gravity
