// The SPH laws of sph_fluid.hpp, each written once as a small evaluator:
//
//   EquationOfState  p = max(floor, c² (ρ − ρ0))                    (eq. 2.9)
//   DensityLaw       ρ_i = Σ_j m_j W_poly6(r_ij)                     (eq. 2.3, 2.11)
//   PressureLaw      f_i = −Σ_j m_j (p_i + p_j) / (2 ρ_j) ∇W_spiky    (eq. 2.8)
//   ViscosityLaw     f_i = μ Σ_j m_j (v_j − v_i) / ρ_j ∇²W_visc       (eq. 2.10)
//   GradientCorrection  L_i = (Σ_j V_j ∇W_ij ⊗ (x_i − x_j))⁻¹, applied to the
//                    pressure force when sph.gradient_correction is on
//
// and SphLaws, the one set of them built from SphParameters that every driver
// takes: the scalar grid loop and the SIMD grid loop with its scalar tail
// (sph/grid_passes.hpp, src/sph/grid_passes_simd.cpp) and the thesis's hash
// path (sph_fluid.hpp). A new law is a new evaluator here plus its test
// (tests/sph/laws_test.cpp).
//
// Shape of an evaluator: plain data (its constants, in Real) and evaluate
// functions templated over the value type V, so that the same arithmetic runs
// on Real (scalar loops) and on xsimd batches (the SIMD loop, one pair per
// lane). Contract of every pair function: it is called only for pairs with
// r < h (the caller tests r² < h² and masks or skips the others; outside, the
// value is meaningless, not 0), takes the kernel's gap (h² − r² or h − r,
// from SphLaws::gap2/gap: one h for all the laws, so that a pair computes it
// once) and returns the pair's part of the sum with the constant factors left
// out; the factors (norm) are applied once per particle, after the sum, so
// that a pair costs no division but 1/r.
//
// The evaluate functions are force-inlined: the SIMD copies instantiate them
// (with batches and, in their scalar tails, with Real) inside code compiled for
// AVX2/AVX-512, and an out-of-line copy would be an inline function shared
// with baseline code (docs/ARCHITECTURE.md, tools/check_simd_objects.sh).
// Only +, −, ×, and max() (found by argument-dependent lookup for batches:
// xsimd::max) are used, so this header needs no xsimd.
//
// Units: SI (m, kg, s; ρ in kg/m³, p in Pa, μ in Pa·s).
#pragma once

#include <limits>
#include <type_traits>

#include "swirl/sph/kernels.hpp"
#include "swirl/sph/parameters.hpp"

#define SWIRL_LAW_INLINE [[gnu::always_inline]] inline

namespace swirl::sph {

namespace law_detail {

// std::max(a, b) for scalars (a < b ? b : a: the same value for the same
// operands, NaN and signed zeros included); xsimd::max for batches.
template <class V>
SWIRL_LAW_INLINE V max_of(const V& a, const V& b) {
  if constexpr (std::is_floating_point_v<V>) {
    return a < b ? b : a;
  } else {
    return max(a, b);
  }
}

}  // namespace law_detail

// Equation of state (eq. 2.9), with an optional floor:
//   p = max(floor, c² (ρ − ρ0))
// floor = −∞ keeps the thesis's equation (tension where ρ < ρ0); floor = 0 is
// NegativePressure::Zero (see sph_fluid.hpp for why).
template <class Real>
struct EquationOfState {
  Real rest_density = 1000;                                 // ρ0, kg/m³
  Real c2 = 100;                                            // c², m²/s²
  Real floor = -std::numeric_limits<Real>::infinity();      // Pa

  template <class V>
  SWIRL_LAW_INLINE V pressure(const V& rho) const {
    return law_detail::max_of(V(floor), V(c2) * (rho - V(rest_density)));
  }
};

// Density (eq. 2.3 with W_poly6, eq. 2.11):
//   ρ_i = Σ_j m_j W_poly6(r_ij) = norm · Σ_j m_j (h² − r_ij²)³,   norm = 315 / (64 π h⁹)
// the sum over every j with r_ij < h, i itself included (r = 0).
// term() is one j's m_j (h² − r²)³ from d = h² − r² (SphLaws::gap2(r²): no
// square root); density() applies norm to the finished sum.
template <class Real>
struct DensityLaw {
  Real norm = 0;  // 1/m⁹

  template <class V>
  SWIRL_LAW_INLINE V term(const V& m_j, const V& d) const {
    return m_j * d * d * d;
  }
  template <class V>
  SWIRL_LAW_INLINE V density(const V& sum) const {
    return V(norm) * sum;
  }
};

// Pressure force (eq. 2.8) with ∇W_spiky (eq. 2.13) and V_j = m_j / ρ_j:
//   f_i = −Σ_j m_j (p_i + p_j) / (2 ρ_j) ∇W_spiky(r_ij)
//       = norm · Σ_j (p_i V_j + p_j V_j) (h − r)² / r · r⃗_ij,   r⃗_ij = x_i − x_j
//   norm = 45 / (π h⁶) · ½   (the ½ of the thesis's form; 1 with PressureForm::Consistent)
// norm > 0: a positive pressure pushes i away from j. term() is one j's
// (p_i V_j + p_j V_j) (h − r)²/r, the factor of r⃗_ij, from q = h − r
// (SphLaws::gap(r)) and 1/r, which the caller computes from the same r², as
// exactly as it can; the caller takes r = 0 out (e.g. 1/r = 0 there: the
// direction is undefined and the pair contributes nothing). p_j V_j comes
// precomputed per particle (the density pass leaves it).
template <class Real>
struct PressureLaw {
  Real norm = 0;  // 1/m⁶

  template <class V>
  SWIRL_LAW_INLINE V term(const V& p_i, const V& vol_j, const V& pvol_j, const V& q, const V& inv_r) const {
    return (p_i * vol_j + pvol_j) * (q * q * inv_r);
  }
};

// Viscosity force (eq. 2.10) with ∇²W_viscosity (eq. 2.15) and V_j = m_j / ρ_j:
//   f_i = μ Σ_j m_j (v_j − v_i) / ρ_j ∇²W_visc(r_ij)
//       = norm · Σ_j V_j (h − r) (v_j − v_i),   norm = μ · 45 / (π h⁶)
// term() is one j's V_j (h − r), the factor of (v_j − v_i), from q = h − r
// (SphLaws::gap(r)); it is finite at r = 0.
template <class Real>
struct ViscosityLaw {
  Real norm = 0;  // Pa·s/m⁶

  template <class V>
  SWIRL_LAW_INLINE V term(const V& vol_j, const V& q) const {
    return vol_j * q;
  }
};

// Kernel-gradient correction (Bonet & Lok 1999, "renormalisation"), for the
// pressure force only:
//   M_i = Σ_j V_j ∇W_spiky(r_ij) ⊗ (x_j − x_i)
//       = norm · Σ_j V_j (h − r)² / r · r⃗_ij ⊗ r⃗_ij,   r⃗_ij = x_i − x_j,  norm = 45 / (π h⁶)
// is the identity in the continuum; on particles it is not (on a cubic lattice
// at h = 1.93 spacings it is 0.947·I), so a pressure gradient is felt too
// weakly and a fluid at rest under gravity settles to a pressure too high by
// that factor. The corrected force is L_i f_i with L_i = M_i⁻¹: exact for a
// linear pressure field, but no longer antisymmetric (momentum is not
// conserved to rounding). Where M_i is nearly singular (a free surface: the
// half kernel's M has a determinant near 1/8) the correction would amplify
// the surface's one-sided sum, so L_i = I where det M_i < kMinDeterminant.
// term() is one j's V_j (h − r)²/r, the factor of r⃗_ij ⊗ r⃗_ij (from the same
// q = h − r and 1/r as the pressure term; 0 at r = 0); the six sums are
// xx, xy, xz, yy, yz, zz.
template <class Real>
struct GradientCorrection {
  static constexpr Real kMinDeterminant = Real(0.5);
  Real norm = 0;  // 1/m⁶

  template <class V>
  SWIRL_LAW_INLINE V term(const V& vol_j, const V& q, const V& inv_r) const {
    return vol_j * (q * q * inv_r);
  }

  // L = (norm · sums)⁻¹ as xx, xy, xz, yy, yz, zz; the identity where the
  // matrix is too close to singular (see above) or not finite.
  void inverse(const Real (&sums)[6], Real (&out)[6]) const {
    const Real a = norm * sums[0], b = norm * sums[1], c = norm * sums[2];
    const Real d = norm * sums[3], e = norm * sums[4], f = norm * sums[5];
    // Cofactors of the symmetric matrix [[a b c] [b d e] [c e f]].
    const Real A = d * f - e * e, B = c * e - b * f, C = b * e - c * d;
    const Real det = a * A + b * B + c * C;
    if (!(det >= kMinDeterminant) || !(det < std::numeric_limits<Real>::infinity())) {
      out[0] = out[3] = out[5] = Real(1);
      out[1] = out[2] = out[4] = Real(0);
      return;
    }
    const Real inv = Real(1) / det;
    out[0] = A * inv;
    out[1] = B * inv;
    out[2] = C * inv;
    out[3] = (a * f - c * c) * inv;
    out[4] = (b * c - a * e) * inv;
    out[5] = (a * d - b * b) * inv;
  }

  // (px, py, pz) ← L (px, py, pz), L as inverse() gives it.
  SWIRL_LAW_INLINE static void apply(const Real (&L)[6], Real& px, Real& py, Real& pz) {
    const Real x = px, y = py, z = pz;
    px = L[0] * x + L[1] * y + L[2] * z;
    py = L[1] * x + L[3] * y + L[4] * z;
    pz = L[2] * x + L[4] * y + L[5] * z;
  }
};

// Adds one pair's t · r⃗ ⊗ r⃗ to the six sums of GradientCorrection.
template <class Real>
SWIRL_LAW_INLINE void add_correction_term(Real t, Real dx, Real dy, Real dz, Real (&sums)[6]) {
  sums[0] += t * dx * dx;
  sums[1] += t * dx * dy;
  sums[2] += t * dx * dz;
  sums[3] += t * dy * dy;
  sums[4] += t * dy * dz;
  sums[5] += t * dz * dz;
}

// The laws of one fluid, built once from its parameters (in Real: the
// constants every driver uses are these, rounded once).
template <class Real>
struct SphLaws {
  // Support radius and its square, m, m²: the pairs are r² < h², and the gaps
  // below are the kernels' shared factors, so that one h serves every law.
  Real h = 1, h2 = 1;
  EquationOfState<Real> eos;
  DensityLaw<Real> density;
  PressureLaw<Real> pressure;
  ViscosityLaw<Real> viscosity;
  GradientCorrection<Real> correction;
  bool corrected = false;  // sph.gradient_correction: L_i applied to the pressure sums

  SphLaws() = default;
  explicit SphLaws(const SphParameters& params)
      : SphLaws(Real(params.smoothing_length),
                {Real(params.rest_density), Real(params.sound_speed * params.sound_speed),
                 params.negative_pressure == NegativePressure::Zero ? Real(0) : -std::numeric_limits<Real>::infinity()},
                Real(params.viscosity), params.pressure_form) {
    corrected = params.gradient_correction;
  }
  // From the constants in Real: h (m), the equation of state, μ (Pa·s) and the form of eq. 2.8.
  SphLaws(Real h_, const EquationOfState<Real>& eos_, Real mu, PressureForm form) : h(h_), h2(h_ * h_), eos(eos_) {
    density.norm = Poly6<Real>(h).norm;
    // The spiky gradient's norm is negative (∇W points back to j): its
    // negative is the push away from j.
    const Real half = form == PressureForm::Thesis ? Real(0.5) : Real(1);
    pressure.norm = -Spiky<Real>(h).grad_norm * half;
    viscosity.norm = mu * Viscosity<Real>(h).laplacian_norm;
    correction.norm = -Spiky<Real>(h).grad_norm;
  }

  // d = h² − r², the factor of W_poly6 (the density law's argument; > 0 for
  // the pairs, r² < h²).
  template <class V>
  SWIRL_LAW_INLINE V gap2(const V& r2) const {
    return V(h2) - r2;
  }

  // q = h − r, the factor both force kernels share (∇W_spiky ∝ (h − r)²,
  // ∇²W_visc ∝ h − r), clamped at 0: r computed as r² · (1/r) may exceed h by
  // a rounding for r² < h². One h for both laws, so that a pair computes it once.
  template <class V>
  SWIRL_LAW_INLINE V gap(const V& r) const {
    return law_detail::max_of(V(h) - r, V(Real(0)));
  }

  // a_i = f_i / ρ_i (eq. 2.6) from the unnormalised sums of particle i:
  // pressure_sum = Σ_j PressureLaw::term · r⃗_ij, viscosity_sum = Σ_j ViscosityLaw::term · (v_j − v_i)
  // (one component each).
  SWIRL_LAW_INLINE Real acceleration(Real pressure_sum, Real viscosity_sum, Real inv_rho) const {
    return (pressure.norm * pressure_sum + viscosity.norm * viscosity_sum) * inv_rho;
  }
};

// DFSPH's kernels (sph.kernel; sph/dfsph_passes.hpp), scalar:
//   W(r)  for the density           ρ_i = Σ_j m_j W(r_ij)
//   ∇W_ij = gradient(r) · r⃗_ij      (r⃗_ij = x_i − x_j)
// "cubic_spline": Monaghan's W and its own gradient (CubicSpline);
// "thesis": W_poly6 and ∇W_spiky, the thesis's pair (the gradient is not the
// density kernel's, so DFSPH's density prediction is only approximately the
// density that follows; kept for comparison with the thesis's solver).
template <class Real>
struct DfsphKernel {
  DfsphKernel(SphKernel kind, Real h_)
      : h(h_), h2(h_ * h_), cubic(kind == SphKernel::CubicSpline), poly6(h_), spiky(h_), spline(h_) {}

  // W at distance r (r² given as well: poly6 takes it).
  Real w(Real r2, Real r) const { return cubic ? spline(r) : poly6(r2); }
  // The factor of r⃗_ij; 0 at r = 0.
  Real gradient(Real r) const { return cubic ? spline.gradient_factor(r) : spiky.gradient_factor(r); }

  Real h, h2;
  bool cubic;
  Poly6<Real> poly6;
  Spiky<Real> spiky;
  CubicSpline<Real> spline;
};

}  // namespace swirl::sph

#undef SWIRL_LAW_INLINE
