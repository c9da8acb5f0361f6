// Müller kernels: normalisation, gradients, support.
#include "swirl/sph/kernels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {

using namespace swirl::sph;

template <class Real>
class KernelTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(KernelTest, Precisions);

// ∫ W dV over the ball of radius h = ∫₀ʰ 4π r² W(r) dr by composite Simpson
// with 2000 intervals: the quadrature error is far below 1e-6 for these
// polynomial kernels, so the tolerance is set by the precision.
template <class F>
double ball_integral(F w, double h) {
  const int n = 2000;
  const double dr = h / n;
  double sum = 0;
  for (int k = 0; k <= n; ++k) {
    const double r = k * dr;
    const double f = 4 * std::numbers::pi * r * r * w(r);
    sum += f * (k == 0 || k == n ? 1 : (k % 2 ? 4 : 2));
  }
  return sum * dr / 3;
}

template <class Real>
double tol() { return std::is_same_v<Real, float> ? 2e-5 : 1e-9; }

TYPED_TEST(KernelTest, Poly6AndSpikyIntegrateToOne) {
  using Real = TypeParam;
  for (double h : {0.01, 0.5, 3.0}) {
    const Poly6<Real> poly6{Real(h)};
    const Spiky<Real> spiky{Real(h)};
    const Viscosity<Real> visc{Real(h)};
    // Relative to h³·W scale, so the float tolerance is meaningful at any h.
    EXPECT_NEAR(ball_integral([&](double r) { return double(poly6(Real(r * r))); }, h), 1.0, tol<Real>()) << h;
    EXPECT_NEAR(ball_integral([&](double r) { return double(spiky(Real(r))); }, h), 1.0, tol<Real>()) << h;
    // W_viscosity is singular (h/2r) at 0 but integrable; r² cancels it.
    EXPECT_NEAR(ball_integral([&](double r) { return double(visc(Real(r))); }, h), 1.0, 1e3 * tol<Real>()) << h;
  }
}

TYPED_TEST(KernelTest, GradientsMatchFiniteDifferences) {
  using Real = TypeParam;
  const double h = 0.7;
  const Poly6<Real> poly6{Real(h)};
  const Spiky<Real> spiky{Real(h)};
  const Viscosity<Real> visc{Real(h)};
  // Central differences in double of the kernel evaluated in Real; step and
  // tolerance scaled to the precision (truncation ~d², round-off ~eps/d).
  const double d = std::is_same_v<Real, float> ? 1e-3 : 1e-6;
  const double rel = std::is_same_v<Real, float> ? 2e-2 : 1e-6;
  for (double r : {0.05, 0.2, 0.35, 0.5, 0.65}) {
    // d/dr W along r: the radial component of ∇W (∇W = factor · r⃗, so factor·r).
    const double fd_poly6 = (double(poly6(Real((r + d) * (r + d)))) - double(poly6(Real((r - d) * (r - d))))) / (2 * d);
    EXPECT_NEAR(double(poly6.gradient_factor(Real(r * r))) * r, fd_poly6, rel * std::abs(fd_poly6)) << r;
    const double fd_spiky = (double(spiky(Real(r + d))) - double(spiky(Real(r - d)))) / (2 * d);
    EXPECT_NEAR(double(spiky.gradient_factor(Real(r))) * r, fd_spiky, rel * std::abs(fd_spiky)) << r;
    // ∇²W = W'' + 2W'/r for a radial function.
    auto w = [&](double s) { return double(visc(Real(s))); };
    const double dd = std::is_same_v<Real, float> ? 1e-2 : 1e-4;
    const double lap = (w(r + dd) - 2 * w(r) + w(r - dd)) / (dd * dd) + 2 / r * (w(r + dd) - w(r - dd)) / (2 * dd);
    EXPECT_NEAR(double(visc.laplacian(Real(r))), lap, (std::is_same_v<Real, float> ? 5e-2 : 1e-5) * std::abs(lap)) << r;
    EXPECT_GT(visc.laplacian(Real(r)), Real(0));
  }
}

TYPED_TEST(KernelTest, CubicSplineIntegratesToOne) {
  using Real = TypeParam;
  for (double h : {0.01, 0.5, 3.0}) {
    const CubicSpline<Real> w{Real(h)};
    // q = ½ falls on a Simpson node (interval 1000 of 2000), so the kink of
    // the second derivative there costs no accuracy.
    EXPECT_NEAR(ball_integral([&](double r) { return double(w(Real(r))); }, h), 1.0, tol<Real>()) << h;
  }
  // Monaghan's value at the centre, 1/(π ℓ³) with ℓ = h/2.
  const double h = 0.4, l = h / 2;
  EXPECT_NEAR(double(CubicSpline<Real>(Real(h))(Real(0))), 1 / (std::numbers::pi * l * l * l),
              (std::is_same_v<Real, float> ? 1e-6 : 1e-13) / (l * l * l));
}

TYPED_TEST(KernelTest, CubicSplineGradientMatchesFiniteDifferences) {
  using Real = TypeParam;
  const double h = 0.7;
  const CubicSpline<Real> w{Real(h)};
  const double d = std::is_same_v<Real, float> ? 1e-3 : 1e-6;
  const double rel = std::is_same_v<Real, float> ? 2e-2 : 1e-6;
  // Both branches, and near the joint (q = 0.5 at r = 0.35) from either side.
  for (double r : {0.03, 0.1, 0.2, 0.34, 0.36, 0.5, 0.65}) {
    const double fd = (double(w(Real(r + d))) - double(w(Real(r - d)))) / (2 * d);
    EXPECT_NEAR(double(w.gradient_factor(Real(r))) * r, fd, rel * std::abs(fd)) << r;
    EXPECT_LT(w.gradient_factor(Real(r)), Real(0)) << r;  // W decreases outward
  }
  // Continuous at the joint: the two branches agree to rounding.
  const Real joint = Real(0.35);
  EXPECT_NEAR(double(w.gradient_factor(joint)), double(w.gradient_factor(joint * (Real(1) + Real(1e-6)))),
              1e-4 * std::abs(double(w.gradient_factor(joint))));
  EXPECT_EQ(w.gradient_factor(Real(0)), Real(0));
  EXPECT_EQ(w(Real(h)), Real(0));
  EXPECT_EQ(w.gradient_factor(Real(h)), Real(0));
  EXPECT_GT(w(Real(0.99 * h)), Real(0));
}

TYPED_TEST(KernelTest, AllVanishAtAndBeyondTheSupport) {
  using Real = TypeParam;
  const Real h = Real(0.3);
  const Poly6<Real> poly6(h);
  const Spiky<Real> spiky(h);
  const Viscosity<Real> visc(h);
  for (Real r : {h, Real(1.0001) * h, Real(2) * h, Real(100)}) {
    EXPECT_EQ(poly6(r * r), Real(0));
    EXPECT_EQ(poly6.gradient_factor(r * r), Real(0));
    EXPECT_EQ(spiky(r), Real(0));
    EXPECT_EQ(spiky.gradient_factor(r), Real(0));
    EXPECT_EQ(visc(r), Real(0));
    EXPECT_EQ(visc.laplacian(r), Real(0));
  }
  EXPECT_EQ(spiky.gradient_factor(Real(0)), Real(0));  // defined as 0 at r = 0
  EXPECT_GT(poly6(Real(0)), Real(0));
  // Just inside the support every kernel is still positive.
  EXPECT_GT(poly6(Real(0.99) * h * h), Real(0));
  EXPECT_GT(spiky(Real(0.99) * h), Real(0));
  EXPECT_LT(spiky.gradient_factor(Real(0.5) * h), Real(0));
}

}  // namespace
