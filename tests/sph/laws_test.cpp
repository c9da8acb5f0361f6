// The SPH law evaluators (sph/laws.hpp), each against its equation written
// out here independently (in double, from the thesis's formulas), and the
// batch instantiation against the scalar one.
#include "swirl/sph/laws.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include <xsimd/xsimd.hpp>

// GCC 12 reports the deliberately undefined pass-through operand of the
// AVX-512 max intrinsic xsimd calls as uninitialized where it is inlined
// (as in src/sph/grid_passes_simd.cpp): a known false positive.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace {

using namespace swirl::sph;
constexpr double kPi = std::numbers::pi;

template <class Real>
class LawTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(LawTest, Precisions);

template <class Real>
double rel_tol() {
  return std::is_same_v<Real, float> ? 2e-6 : 1e-14;
}

SphParameters parameters(double h, PressureForm form = PressureForm::Thesis,
                         NegativePressure negative = NegativePressure::Keep) {
  SphParameters s;
  s.smoothing_length = h;
  s.rest_density = 1000;
  s.sound_speed = 3;
  s.viscosity = 0.25;
  s.pressure_form = form;
  s.negative_pressure = negative;
  return s;
}

TYPED_TEST(LawTest, EquationOfStateAndItsFloor) {
  using Real = TypeParam;
  const SphLaws<Real> keep(parameters(0.1));
  const SphLaws<Real> zero(parameters(0.1, PressureForm::Thesis, NegativePressure::Zero));
  // p = c² (ρ − ρ0), c = 3 m/s, ρ0 = 1000 kg/m³: exact in float for these values.
  EXPECT_EQ(keep.eos.pressure(Real(1002)), Real(18));
  EXPECT_EQ(keep.eos.pressure(Real(990)), Real(-90));  // the thesis's tension
  EXPECT_EQ(zero.eos.pressure(Real(1002)), Real(18));
  EXPECT_EQ(zero.eos.pressure(Real(990)), Real(0));  // clamped
  EXPECT_EQ(keep.eos.pressure(Real(1000)), Real(0));
}

// ρ_i = Σ_j m_j · 315/(64π h⁹) (h² − r²)³, i itself included.
TYPED_TEST(LawTest, DensityIsTheMassWeightedPoly6Sum) {
  using Real = TypeParam;
  const double h = 0.05;
  const SphLaws<Real> laws(parameters(h));
  const double m[] = {0.02, 0.03, 0.011, 0.04};
  const double r[] = {0.0, 0.01, 0.033, 0.049};  // the first is i itself
  double expected = 0;
  Real sum = 0;
  for (int k = 0; k < 4; ++k) {
    expected += m[k] * 315 / (64 * kPi * std::pow(h, 9)) * std::pow(h * h - r[k] * r[k], 3);
    sum += laws.density.term(Real(m[k]), laws.gap2(Real(r[k] * r[k])));
  }
  EXPECT_NEAR(double(laws.density.density(sum)), expected, 4 * rel_tol<Real>() * expected);
}

// f_i = −m_j (p_i + p_j)/(2 ρ_j) ∇W_spiky, ∇W_spiky = −45/(π h⁶) (h − r)² r⃗/r
// (without the ½ in the consistent form); the law gives norm · term · r⃗.
TYPED_TEST(LawTest, PressureTermIsEquation2_8) {
  using Real = TypeParam;
  const double h = 0.1, m_j = 0.5, rho_j = 1010, p_i = 30, p_j = -12;
  const double rv[3] = {0.02, -0.03, 0.05};
  const double r = std::sqrt(rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2]);
  for (PressureForm form : {PressureForm::Thesis, PressureForm::Consistent}) {
    const SphLaws<Real> laws(parameters(h, form));
    const double half = form == PressureForm::Thesis ? 0.5 : 1.0;
    const double vol_j = m_j / rho_j;
    const Real term = laws.pressure.term(Real(p_i), Real(vol_j), Real(p_j * vol_j), laws.gap(Real(r)), Real(1 / r));
    for (int a = 0; a < 3; ++a) {
      const double grad = -45 / (kPi * std::pow(h, 6)) * (h - r) * (h - r) * rv[a] / r;
      const double expected = -m_j * (p_i + p_j) * half / rho_j * grad;
      EXPECT_NEAR(double(laws.pressure.norm) * double(term) * rv[a], expected, 8 * rel_tol<Real>() * std::abs(expected))
          << a;
    }
    // A positive pressure pushes i away from j (along r⃗ = x_i − x_j).
    EXPECT_GT(double(laws.pressure.norm) * double(term), 0.0);
  }
}

// f_i = μ m_j (v_j − v_i)/ρ_j · 45/(π h⁶) (h − r); the law gives norm · term · (v_j − v_i).
TYPED_TEST(LawTest, ViscosityTermIsEquation2_10) {
  using Real = TypeParam;
  const double h = 0.1, mu = 0.25, m_j = 0.5, rho_j = 990, r = 0.037, dv = -0.8;
  const SphLaws<Real> laws(parameters(h));
  const double expected = mu * m_j * dv / rho_j * 45 / (kPi * std::pow(h, 6)) * (h - r);
  const double got = double(laws.viscosity.norm) * double(laws.viscosity.term(Real(m_j / rho_j), laws.gap(Real(r)))) * dv;
  EXPECT_NEAR(got, expected, 8 * rel_tol<Real>() * std::abs(expected));
  // Finite at r = 0 (unlike the pressure term, which the caller takes out there).
  EXPECT_EQ(laws.viscosity.term(Real(2), laws.gap(Real(0))), Real(2) * Real(h));
  // The gap h − r is clamped at 0 just outside h (r from r² · (1/r) may round past h).
  EXPECT_EQ(laws.gap(Real(h) * Real(1.0001)), Real(0));
}

TYPED_TEST(LawTest, AccelerationDividesTheNormalisedSumsByDensity) {
  using Real = TypeParam;
  const SphLaws<Real> laws(parameters(0.1));
  const double sp = 3.5, sv = -1.25, rho = 1005;
  const double expected = (double(laws.pressure.norm) * sp + double(laws.viscosity.norm) * sv) / rho;
  EXPECT_NEAR(double(laws.acceleration(Real(sp), Real(sv), Real(1 / rho))), expected,
              8 * rel_tol<Real>() * std::abs(expected));
}

// The gradient correction: M_i from a full cubic lattice is c·I with c the
// spiky gradient's lattice deficit (0.947 at h = 1.93 spacings, sph/laws.hpp),
// L_i = M_i⁻¹ undoes it, a general symmetric M is inverted (L·M = I), and a
// nearly singular M (a free surface's half kernel) gets no correction.
TYPED_TEST(LawTest, GradientCorrectionInvertsTheLatticeMoment) {
  using Real = TypeParam;
  const double s = 0.01, h = 1.93 * s, V = s * s * s;
  const SphLaws<Real> laws(parameters(h));
  EXPECT_NEAR(double(laws.correction.norm), 45 / (kPi * std::pow(h, 6)), 1e-6 * 45 / (kPi * std::pow(h, 6)));
  Real m6[6] = {}, half[6] = {};
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j)
      for (int k = -2; k <= 2; ++k) {
        const double dx = i * s, dy = j * s, dz = k * s, r = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (r == 0 || r >= h) continue;
        const Real t = laws.correction.term(Real(V), laws.gap(Real(r)), Real(1 / r));
        add_correction_term(t, Real(dx), Real(dy), Real(dz), m6);
        if (k > 0 || (k == 0 && (j > 0 || (j == 0 && i > 0)))) add_correction_term(t, Real(dx), Real(dy), Real(dz), half);
      }
  const double c = double(laws.correction.norm) * double(m6[0]);
  EXPECT_NEAR(c, 0.9467, 5e-4);
  EXPECT_NEAR(double(laws.correction.norm) * double(m6[3]), c, 1e-5);
  EXPECT_NEAR(double(laws.correction.norm) * double(m6[1]), 0.0, 1e-6);
  Real L[6];
  laws.correction.inverse(m6, L);
  EXPECT_NEAR(double(L[0]), 1 / c, 1e-5);
  EXPECT_NEAR(double(L[5]), 1 / c, 1e-5);
  EXPECT_NEAR(double(L[2]), 0.0, 1e-5);
  Real px = Real(2), py = Real(-1), pz = Real(0.5);
  GradientCorrection<Real>::apply(L, px, py, pz);
  EXPECT_NEAR(double(px), 2 / c, 1e-5);
  EXPECT_NEAR(double(py), -1 / c, 1e-5);

  // A general symmetric positive matrix (as sums, before norm).
  const double a[6] = {1.2, 0.1, -0.2, 0.9, 0.15, 1.1};
  Real sums[6];
  for (int q = 0; q < 6; ++q) sums[q] = Real(a[q] / double(laws.correction.norm));
  laws.correction.inverse(sums, L);
  const double M[3][3] = {{a[0], a[1], a[2]}, {a[1], a[3], a[4]}, {a[2], a[4], a[5]}};
  const double Li[3][3] = {{L[0], L[1], L[2]}, {L[1], L[3], L[4]}, {L[2], L[4], L[5]}};
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) {
      double e = 0;
      for (int q = 0; q < 3; ++q) e += Li[r][q] * M[q][col];
      EXPECT_NEAR(e, r == col ? 1.0 : 0.0, 1e-5) << r << ", " << col;
    }

  // Half a lattice (a free surface): det M ≈ 1/8 < 0.5, so L = I.
  laws.correction.inverse(half, L);
  EXPECT_EQ(L[0], Real(1));
  EXPECT_EQ(L[3], Real(1));
  EXPECT_EQ(L[5], Real(1));
  EXPECT_EQ(L[1], Real(0));
}

// The SIMD loop instantiates the same evaluators with batches: lane by lane
// they equal the scalar ones to rounding (FMA contraction may differ).
TYPED_TEST(LawTest, BatchesEvaluateTheSameLaws) {
  using Real = TypeParam;
  using B = xsimd::batch<Real>;
  constexpr std::size_t W = B::size;
  const SphLaws<Real> laws(parameters(0.1));
  alignas(64) Real r[W], m[W], p[W], vol[W];
  for (std::size_t k = 0; k < W; ++k) {
    r[k] = Real(0.1) * Real(k + 1) / Real(W + 1);
    m[k] = Real(0.01) * Real(k + 3);
    p[k] = Real(20) + Real(3) * Real(k);  // no cancellation in p_i V_j + p_j V_j: FMA contraction may differ
    vol[k] = m[k] / Real(1000);
  }
  const B rb = B::load_aligned(r), mb = B::load_aligned(m), pb = B::load_aligned(p), vb = B::load_aligned(vol);
  alignas(64) Real density[W], pressure[W], viscosity[W];
  laws.density.term(mb, laws.gap2(rb * rb)).store_aligned(density);
  laws.pressure.term(B(Real(7)), vb, pb * vb, laws.gap(rb), B(Real(1)) / rb).store_aligned(pressure);
  laws.viscosity.term(vb, laws.gap(rb)).store_aligned(viscosity);
  for (std::size_t k = 0; k < W; ++k) {
    const Real d = laws.density.term(m[k], laws.gap2(r[k] * r[k]));
    const Real f = laws.pressure.term(Real(7), vol[k], p[k] * vol[k], laws.gap(r[k]), Real(1) / r[k]);
    const Real v = laws.viscosity.term(vol[k], laws.gap(r[k]));
    EXPECT_NEAR(double(density[k]), double(d), 8 * rel_tol<Real>() * std::abs(double(d))) << k;
    EXPECT_NEAR(double(pressure[k]), double(f), 8 * rel_tol<Real>() * std::abs(double(f))) << k;
    EXPECT_NEAR(double(viscosity[k]), double(v), 8 * rel_tol<Real>() * std::abs(double(v))) << k;
  }
}

}  // namespace
