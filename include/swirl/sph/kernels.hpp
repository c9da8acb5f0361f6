// The smoothing kernels of Müller et al. 2003, as the thesis uses them
// (section 2.1.1), the cubic spline of Monaghan 1992 (DFSPH's kernel), and
// the cohesion and adhesion splines of Akinci et al. 2013 (surface tension).
// Each is a small evaluator built once for a support radius h (m); all vanish
// for r ≥ h. Units: W in 1/m³, ∇W in 1/m⁴, ∇²W in 1/m⁵; the splines' below.
#pragma once

#include <cmath>
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

// The cubic spline (Monaghan 1992, "Smoothed particle hydrodynamics", eq. 2.6
// with support 2ℓ), written for the support radius h = 2ℓ like the kernels
// above, q = r/h:
//   W(r, h) = k · (6q³ − 6q² + 1)   for 0 ≤ q ≤ ½,    k = 8 / (π h³)
//           = k · 2 (1 − q)³        for ½ < q < 1
// dW/dr    = (k/h) · 6 (3q² − 2q)   for q ≤ ½
//          = −(k/h) · 6 (1 − q)²    for ½ < q < 1
// ∇W = dW/dr · r⃗ / r (r⃗ = x_i − x_j), 0 at r = 0 (dW/dr vanishes there).
// W and its first derivative are continuous at q = ½ and vanish smoothly at
// q = 1, and unlike W_spiky its gradient is the derivative of the density
// kernel itself, which DFSPH's factor α and its density prediction assume.
template <class Real>
struct CubicSpline {
  explicit CubicSpline(Real h_)
      : h(h_), inv_h(Real(1) / h_), norm(Real(8) / (std::numbers::pi_v<Real> * h_ * h_ * h_)),
        grad_norm(Real(48) / (std::numbers::pi_v<Real> * h_ * h_ * h_ * h_)) {}

  Real operator()(Real r) const {
    const Real q = r * inv_h;
    if (q >= Real(1)) return Real(0);
    if (q <= Real(0.5)) return norm * (Real(6) * q * q * (q - Real(1)) + Real(1));
    const Real d = Real(1) - q;
    return norm * Real(2) * d * d * d;
  }
  // ∇W = gradient_factor(r) · r⃗, for r = |r⃗| (grad_norm = 6k/h).
  Real gradient_factor(Real r) const {
    const Real q = r * inv_h;
    if (q >= Real(1) || r <= Real(0)) return Real(0);
    if (q <= Real(0.5)) return grad_norm * (Real(3) * q - Real(2)) * inv_h;  // 6k/h·(3q² − 2q)/r, r = q·h
    const Real d = Real(1) - q;
    return -grad_norm * d * d / r;
  }

  Real h, inv_h, norm, grad_norm;
};

// The cohesion spline of Akinci, Akinci & Teschner 2013 ("Versatile surface
// tension and adhesion for SPH fluids", eq. 2), support h (1/m³):
//   C(r) = 32/(π h⁹) · (h − r)³ r³                for h/2 < r < h
//        = 32/(π h⁹) · (2 (h − r)³ r³ − h⁶/64)    for 0 < r ≤ h/2
// Positive (attraction) beyond about 0.3 h, negative (repulsion) closer in,
// so that cohesion alone does not clump particles; 0 at r = 0 and r ≥ h.
template <class Real>
struct AkinciCohesion {
  explicit AkinciCohesion(Real h_)
      : h(h_), norm(Real(32) / (std::numbers::pi_v<Real> * pow9(h_))), h6_64(pow6(h_) / Real(64)) {}

  Real operator()(Real r) const {
    if (r >= h || r <= Real(0)) return Real(0);
    const Real d = h - r, t = d * d * d * r * r * r;
    return Real(2) * r > h ? norm * t : norm * (Real(2) * t - h6_64);
  }

  Real h, norm, h6_64;

 private:
  static Real pow6(Real x) { const Real x3 = x * x * x; return x3 * x3; }
  static Real pow9(Real x) { const Real x3 = x * x * x; return x3 * x3 * x3; }
};

// The adhesion spline of Akinci et al. 2013 (eq. 7), support h (1/m³):
//   A(r) = 0.007 / h^3.25 · (−4r²/h + 6r − 2h)^¼   for h/2 < r < h, else 0
// (0 at both ends, largest at r = ¾h): a fluid particle is drawn towards a
// boundary particle between half a support and a support away.
template <class Real>
struct AkinciAdhesion {
  explicit AkinciAdhesion(Real h_) : h(h_), norm(Real(0.007) / Real(std::pow(double(h_), 3.25))) {}

  Real operator()(Real r) const {
    if (r >= h || Real(2) * r <= h) return Real(0);
    const Real base = -Real(4) * r * r / h + Real(6) * r - Real(2) * h;
    return base > Real(0) ? norm * std::sqrt(std::sqrt(base)) : Real(0);
  }

  Real h, norm;
};

}  // namespace swirl::sph
