// The smoothing kernels of Müller et al. 2003, as the thesis uses them
// (section 2.1.1). Each is a small evaluator built once for a support radius h
// (m); all vanish for r ≥ h. Units: W in 1/m³, ∇W in 1/m⁴, ∇²W in 1/m⁵.
#pragma once

#include <numbers>

namespace swirl::sph {

// W_poly6(r, h) = 315 / (64 π h⁹) · (h² − r²)³                      (eq. 2.11)
// ∇W_poly6(r, h) = −945 / (32 π h⁹) · (h² − r²)² · r
// Takes r² so that density needs no square root.
template <class Real>
struct Poly6 {
  explicit Poly6(Real h)
      : h2(h * h), norm(Real(315) / (Real(64) * std::numbers::pi_v<Real> * pow9(h))),
        grad_norm(Real(-945) / (Real(32) * std::numbers::pi_v<Real> * pow9(h))) {}

  Real operator()(Real r2) const {
    if (r2 >= h2) return Real(0);
    const Real d = h2 - r2;
    return norm * d * d * d;
  }
  // ∇W = gradient_factor(r²) · r⃗ (r⃗ = x_i − x_j).
  Real gradient_factor(Real r2) const {
    if (r2 >= h2) return Real(0);
    const Real d = h2 - r2;
    return grad_norm * d * d;
  }

  Real h2, norm, grad_norm;

 private:
  static Real pow9(Real h) { const Real h3 = h * h * h; return h3 * h3 * h3; }
};

// W_spiky(r, h) = 15 / (π h⁶) · (h − r)³                             (eq. 2.12)
// ∇W_spiky(r, h) = −45 / (π h⁶) · (h − r)² · r⃗ / |r|                 (eq. 2.13)
// Eq. 2.13 as printed drops the 1/|r|; without it the gradient would not be the
// derivative of eq. 2.12. At r = 0 the gradient is taken as 0 (its direction
// is undefined, and the pair exerts no net force either way).
template <class Real>
struct Spiky {
  explicit Spiky(Real h_)
      : h(h_), norm(Real(15) / (std::numbers::pi_v<Real> * pow6(h_))),
        grad_norm(Real(-45) / (std::numbers::pi_v<Real> * pow6(h_))) {}

  Real operator()(Real r) const {
    if (r >= h) return Real(0);
    const Real d = h - r;
    return norm * d * d * d;
  }
  // ∇W = gradient_factor(r) · r⃗, for r = |r⃗|.
  Real gradient_factor(Real r) const {
    if (r >= h || r <= Real(0)) return Real(0);
    const Real d = h - r;
    return grad_norm * d * d / r;
  }

  Real h, norm, grad_norm;

 private:
  static Real pow6(Real x) { const Real x3 = x * x * x; return x3 * x3; }
};

// W_viscosity(r, h) = −15 / (2π h³) · (−r³/(2h³) + r²/h² + h/(2r) − 1)   (eq. 2.14,
// as printed with a leading minus sign that would make it negative; the kernel
// is the positive one, 15/(2π h³)·(...))
// ∇²W_viscosity(r, h) = 45 / (π h⁶) · (h − r)                           (eq. 2.15)
template <class Real>
struct Viscosity {
  explicit Viscosity(Real h_) : h(h_), laplacian_norm(Real(45) / (std::numbers::pi_v<Real> * pow6(h_))) {}

  Real operator()(Real r) const {
    if (r >= h || r <= Real(0)) return Real(0);
    const Real q = r / h;
    return Real(15) / (Real(2) * std::numbers::pi_v<Real> * h * h * h) *
           (-q * q * q / Real(2) + q * q + Real(1) / (Real(2) * q) - Real(1));
  }
  Real laplacian(Real r) const { return r >= h ? Real(0) : laplacian_norm * (h - r); }

  Real h, laplacian_norm;

 private:
  static Real pow6(Real x) { const Real x3 = x * x * x; return x3 * x3; }
};

}  // namespace swirl::sph
