// The per-pair arithmetic of DFSPH's two solve passes, written once for the
// grid passes (sph/dfsph_passes.hpp) and the passes over the kept pairs
// (sph/dfsph_pairs.hpp), with every fused multiply-add spelled out:
//
//   density change   sum ← sum + g·((v_i − v_j)·r⃗_ij)       g = m_j ∂W/∂r / r
//   pressure         a⃗ ← a⃗ + g·r⃗_ij                         g = m_j (k_i + k_j) ∂W/∂r / r
//
// Why spelled out: with contraction left to the compiler, the same
// expression rounds differently from one loop to another. A loop over the
// kept pairs that GCC vectorised summed rounded products in order (no FMA
// into the sum) while the grid pass fused them, and the two disagreed in the
// last bit for most particles. Here the order and the fusing are this code's:
// fused(a, b, c) is one rounding of a·b + c where the target has FMA (the
// contraction -ffp-contract=fast makes of the plain expression, so the results
// are the bits the passes had before), and a·b + c, two roundings, where it
// has not (the release build without -march=native, which contracts nothing).
// Force-inlined: an explicit-SIMD copy may instantiate them, and must not share
// an out-of-line copy with baseline code (docs/ARCHITECTURE.md).
// Units: those of the passes (g in kg/m⁵ or kg/m⁵·m²/s², r⃗ in m, v in m/s).
#pragma once

#include <cmath>
#include <cstddef>

namespace swirl::sph::detail {

template <class Real>
[[gnu::always_inline]] inline Real fused(Real a, Real b, Real c) {
#if defined(__FMA__)
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

// Δv⃗·r⃗ with Δv⃗ = v_i − v_j, r⃗ = x_i − x_j, as Δv_z r_z + (Δv_x r_x + Δv_y r_y):
// the order GCC's contraction gave the grid pass.
template <class Real>
[[gnu::always_inline]] inline Real velocity_dot(Real dvx, Real dvy, Real dvz, Real dx, Real dy, Real dz) {
  return fused(dvz, dz, fused(dvx, dx, dvy * dy));
}

// sum + g·(Δv⃗·r⃗): the density change's running sum after one pair.
template <class Real>
[[gnu::always_inline]] inline Real density_change_term(Real sum, Real g, Real dvx, Real dvy, Real dvz, Real dx,
                                                       Real dy, Real dz) {
  return fused(g, velocity_dot(dvx, dvy, dvz, dx, dy, dz), sum);
}

}  // namespace swirl::sph::detail
