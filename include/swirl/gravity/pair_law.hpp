// The gravitational laws of swirl, G = 1, Plummer softening ε, each written
// once as a template over the value type V (Real for the scalar code, an xsimd
// batch for the SIMD kernels, one interaction per lane):
//
//   point mass m at d = x_j − x_i (the pair law):
//     a_i += m d / R³,   φ_i −= m / R,                      R = sqrt(|d|² + ε²)
//   cell of mass m, traceless quadrupole Q (Q_ab = Σ m (3 r_a r_b − r² δ_ab),
//   q_zz = −q_xx − q_yy) about its centre of mass, d = centre of mass − x_i:
//     φ_i −= m / R + ½ dᵀQd / R⁵
//     a_i  = −∇φ_i: += (m / R³ + 5/2 dᵀQd / R⁷) d − Qd / R⁵
//   (the quadrupole potential is even in d and Qd odd, so d or r = −d alike).
//
// The only place they are written: the direct sum, every tree walk (Octree,
// LinearOctree) and the interaction kernels (scalar and SIMD) call these, so
// that with λ = 0 a walk adds exactly the direct sum's terms (in another
// order), and the quadrupole of the per-particle walk is the group walk's.
//
// Contract of add_point / add_cell: inv = 1/R as the caller computes it (the
// scalar code exactly, inverse_distance(); the SIMD kernels from a hardware
// estimate), 0 for an interaction that must not count; the sums s (members ax,
// ay, az, phi of type V) get the terms added. A pair at zero softened distance
// (coincident particles and ε = 0) gets inv = 0 and contributes nothing
// instead of inf/NaN: its force has no direction.
//
// The multiply-adds are written as madd(a, b, c) = a·b + c: for Real the
// plain expression (the compiler may fuse it where the target has FMA, as it
// may any a·b + c), for batches xsimd::fma (found by argument-dependent
// lookup: this header needs no xsimd). The templates are force-inlined: the
// SIMD copies instantiate them in code compiled for AVX2/AVX-512, which must
// not emit an inline function shared with baseline code (docs/ARCHITECTURE.md).
//
// Units: as the inputs (lengths as positions, masses as given, G = 1).
#pragma once

#include <cmath>
#include <type_traits>

#define SWIRL_LAW_INLINE [[gnu::always_inline]] inline

namespace swirl::gravity {

namespace law_detail {

template <class V, bool = std::is_floating_point_v<V>>
struct ScalarOf {
  using type = V;
};
template <class V>
struct ScalarOf<V, false> {
  using type = typename V::value_type;
};

// a·b + c
template <class V>
SWIRL_LAW_INLINE V madd(const V& a, const V& b, const V& c) {
  if constexpr (std::is_floating_point_v<V>) {
    return a * b + c;
  } else {
    return fma(a, b, c);
  }
}

// c − a·b
template <class V>
SWIRL_LAW_INLINE V nmadd(const V& a, const V& b, const V& c) {
  if constexpr (std::is_floating_point_v<V>) {
    return c - a * b;
  } else {
    return fnma(a, b, c);
  }
}

}  // namespace law_detail

// 1/R for R² = |d|² + ε² (r2s), 0 where R² = 0: the scalar code's inv.
template <class Real>
inline Real inverse_distance(Real r2s) {
  return r2s > Real(0) ? Real(1) / std::sqrt(r2s) : Real(0);
}

// m/R³ from m/R and 1/R: the point-mass law's factor of d in the acceleration
// (m/R itself is the potential's magnitude).
template <class V>
SWIRL_LAW_INLINE V point_accel(const V& m_inv, const V& inv) {
  return m_inv * (inv * inv);
}

// Point mass m at d: a += m d / R³, φ −= m / R.
template <class V, class Sums>
SWIRL_LAW_INLINE void add_point(const V& dx, const V& dy, const V& dz, const V& m, const V& inv, Sums& s) {
  using law_detail::madd;
  const V m_inv = m * inv;
  const V accel = point_accel(m_inv, inv);
  s.ax = madd(accel, dx, s.ax);
  s.ay = madd(accel, dy, s.ay);
  s.az = madd(accel, dz, s.az);
  s.phi = s.phi - m_inv;
}

// A cell's traceless quadrupole (zz = −xx − yy).
template <class V>
struct Quadrupole {
  V xx, xy, xz, yy, yz, zz;
};

// Cell of mass m and quadrupole Q at d (centre of mass − target):
//   φ −= m/R + ½ dᵀQd/R⁵,   a += (m/R³ + 5/2 dᵀQd/R⁷) d − Qd/R⁵.
// The monopole's m/R³ and the quadrupole's radial 5/2 dᵀQd/R⁷ share one
// coefficient of d.
template <class V, class Sums>
SWIRL_LAW_INLINE void add_cell(const V& dx, const V& dy, const V& dz, const V& m, const Quadrupole<V>& Q, const V& inv,
                               Sums& s) {
  using law_detail::madd;
  using law_detail::nmadd;
  using T = typename law_detail::ScalarOf<V>::type;
  const V inv2 = inv * inv;
  const V m_inv = m * inv;
  const V qx = madd(Q.xx, dx, madd(Q.xy, dy, Q.xz * dz));  // Qd
  const V qy = madd(Q.xy, dx, madd(Q.yy, dy, Q.yz * dz));
  const V qz = madd(Q.xz, dx, madd(Q.yz, dy, Q.zz * dz));
  const V q = madd(dx, qx, madd(dy, qy, dz * qz));  // dᵀQd
  const V inv5 = inv * (inv2 * inv2);
  const V q5 = q * inv5;
  const V radial = madd(V(T(2.5)) * q5, inv2, m_inv * inv2);
  s.ax = madd(radial, dx, nmadd(qx, inv5, s.ax));
  s.ay = madd(radial, dy, nmadd(qy, inv5, s.ay));
  s.az = madd(radial, dz, nmadd(qz, inv5, s.az));
  s.phi = s.phi - madd(V(T(0.5)), q5, m_inv);
}

// The pair law for one pair at d = x_j − x_i (scalar code).
template <class Real>
struct PairTerm {
  Real accel;      // m / (|r|² + ε²)^{3/2}: multiply by r for the acceleration
  Real potential;  // −m / sqrt(|r|² + ε²)
};

template <class Real>
inline PairTerm<Real> pair_term(Real dx, Real dy, Real dz, Real mass, Real eps2) {
  const Real inv = inverse_distance(dx * dx + dy * dy + dz * dz + eps2);
  const Real m_inv = mass * inv;
  return {point_accel(m_inv, inv), -m_inv};
}

// Per-particle sums of the laws (scalar code).
template <class Real>
struct Accumulator {
  Real ax = 0, ay = 0, az = 0, phi = 0;

  // The pair law of a particle of mass m at d = x_j − x_i.
  void add(Real dx, Real dy, Real dz, Real mass, Real eps2) {
    add_point(dx, dy, dz, mass, inverse_distance(dx * dx + dy * dy + dz * dz + eps2), *this);
  }
};

}  // namespace swirl::gravity

#undef SWIRL_LAW_INLINE
