// The softened Newtonian pair law, G = 1, Plummer softening ε:
//
//   a_i += m_j (x_j − x_i) / (|r|² + ε²)^{3/2},   φ_i −= m_j / sqrt(|r|² + ε²),   r = x_j − x_i
//
// The only place it is evaluated: the direct sum and every tree walk call it,
// so that with λ = 0 the walk adds exactly the direct sum's terms (in another
// order). A pair at zero softened distance (coincident particles and ε = 0)
// contributes nothing instead of inf/NaN: its force has no direction.
#pragma once

#include <cmath>

namespace swirl::gravity {

template <class Real>
struct PairTerm {
  Real accel;      // m / (|r|² + ε²)^{3/2}: multiply by r for the acceleration
  Real potential;  // −m / sqrt(|r|² + ε²)
};

template <class Real>
inline PairTerm<Real> pair_term(Real dx, Real dy, Real dz, Real mass, Real eps2) {
  const Real r2 = dx * dx + dy * dy + dz * dz + eps2;
  const Real inv = r2 > Real(0) ? Real(1) / std::sqrt(r2) : Real(0);
  const Real m_inv = mass * inv;
  return {m_inv * inv * inv, -m_inv};
}

// Per-particle sums of the pair law.
template <class Real>
struct Accumulator {
  Real ax = 0, ay = 0, az = 0, phi = 0;

  void add(Real dx, Real dy, Real dz, Real mass, Real eps2) {
    const PairTerm<Real> t = pair_term(dx, dy, dz, mass, eps2);
    ax += t.accel * dx;
    ay += t.accel * dy;
    az += t.accel * dz;
    phi += t.potential;
  }
};

}  // namespace swirl::gravity
