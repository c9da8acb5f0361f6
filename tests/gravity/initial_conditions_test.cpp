// Initial conditions against their closed forms (docs: VALIDATION.md), within
// sampling error: 4 standard deviations, so a correct sampler fails about once
// in 16 000 checks, and the seeds are fixed anyway.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/initial_conditions.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class InitialConditionsTest : public ::testing::Test {};
TYPED_TEST_SUITE(InitialConditionsTest, testing::Precisions);

constexpr double kCut = 0.999;  // PlummerOptions' default mass cut

// ∫₀^c f(m) dm by the midpoint rule (f smooth on (0, c)).
template <class F>
double integrate(F f, double c) {
  constexpr int steps = 200000;
  double s = 0;
  for (int k = 0; k < steps; ++k) s += f(c * (k + 0.5) / steps);
  return s * c / steps;
}

// Radius holding mass fraction m of a Plummer sphere: a / sqrt(m^{−2/3} − 1).
double plummer_radius(double m) { return kPlummerScale / std::sqrt(std::pow(m, -2.0 / 3.0) - 1); }

template <class Real>
double potential_energy_exact(const ParticleSet<Real>& p) {
  GravityField<double> f;
  const ParticleSet<double> d = testing::to_double(p);
  direct_sum(d, 0.0, 128, f);
  double w = 0;
  for (std::size_t i = 0; i < d.size(); ++i) w += 0.5 * d.mass[i] * f.potential[i];
  return w;
}

TYPED_TEST(InitialConditionsTest, PlummerLagrangianRadiiFollowTheMassProfile) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const ParticleSet<Real> p = plummer<Real>(n, 1);
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = norm(p.position.get(i).template cast<double>());
  std::sort(r.begin(), r.end());
  for (double m : {0.1, 0.5, 0.9}) {
    // The sample's fraction inside a radius is binomial, σ_m = sqrt(m(1 − m)/N);
    // fractions are of the cut sphere, i.e. m·cut of the full one.
    const double sigma = std::sqrt(m * (1 - m) / n);
    const double measured = r[std::size_t(m * n)];
    EXPECT_GT(measured, plummer_radius((m - 4 * sigma) * kCut)) << "m = " << m;
    EXPECT_LT(measured, plummer_radius((m + 4 * sigma) * kCut)) << "m = " << m;
  }
  EXPECT_NEAR(r[n / 2], 0.7686, 0.02);  // the half-mass radius of VALIDATION.md
}

TYPED_TEST(InitialConditionsTest, PlummerKineticEnergyAndMassAreHenonUnits) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const ParticleSet<Real> p = plummer<Real>(n, 2);
  double mass = 0, k = 0, k2 = 0;
  Vec3d mx{}, mv{};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d v = p.velocity.get(i).template cast<double>();
    const double e = 0.5 * dot(v, v);
    mass += p.mass[i];
    k += p.mass[i] * e;
    k2 += e * e;
    mx += double(p.mass[i]) * p.position.get(i).template cast<double>();
    mv += double(p.mass[i]) * v;
  }
  EXPECT_NEAR(mass, 1.0, 1e-5);
  // Centre of mass removed: what is left is rounding of the positions (|x| ≲ 20).
  EXPECT_LT(norm(mx), 1e-4);
  EXPECT_LT(norm(mv), 1e-5);
  // At mass coordinate m, ⟨v²⟩ = |φ|/2 = sqrt(1 − m^{2/3})/2 (structural units),
  // so K = (16/3π)·∫₀^cut sqrt(1 − m^{2/3}) dm / (4·cut) = 1/4 for cut → 1 (0.25025 at 0.999).
  const double expected = 16 / (3 * std::numbers::pi) *
                          integrate([](double m) { return std::sqrt(1 - std::pow(m, 2.0 / 3.0)); }, kCut) / (4 * kCut);
  EXPECT_NEAR(expected, 0.25, 5e-4);
  // K is the mean of N independent ½v²: σ_K = sd(½v²)/√N.
  const double sd = std::sqrt(k2 / n - k * k);
  EXPECT_NEAR(k, expected, 4 * sd / std::sqrt(double(n)));
}

TYPED_TEST(InitialConditionsTest, PlummerIsVirialisedWithEnergyMinusAQuarter) {
  using Real = TypeParam;
  constexpr std::size_t n = 4096;
  const ParticleSet<Real> p = plummer<Real>(n, 3);
  double k = 0;
  for (std::size_t i = 0; i < n; ++i)
    k += 0.5 * double(p.mass[i]) * dot(p.velocity.get(i).template cast<double>(), p.velocity.get(i).template cast<double>());
  const double w = potential_energy_exact(p);  // unsoftened
  // Expected W: −∫₀^cut m/r(m) dm for the cut sphere, masses renormalised to
  // 1 (÷ cut²), Hénon lengths (× 16/3π), and N(N−1) pairs instead of N²
  // (× (1 − 1/N)): −0.50084 here, E = K + W = −0.2506 (−1/4 for N → ∞, cut → 1).
  const double w_expected = -16 / (3 * std::numbers::pi) / (kCut * kCut) *
                            integrate([](double m) { return m * std::sqrt(std::pow(m, -2.0 / 3.0) - 1); }, kCut) *
                            (1 - 1.0 / n);
  EXPECT_NEAR(w_expected, -0.5, 2e-3);
  // Sampling spread, measured over 400 spheres (N = 1024) and 40 (N = 4096):
  // σ_W ≈ 0.33/√N, σ_E ≈ 0.33/√N, σ(2K/|W|) ≈ 0.8/√N.
  const double root_n = std::sqrt(double(n));
  EXPECT_NEAR(w, w_expected, 4 * 0.33 / root_n);
  EXPECT_NEAR(k + w, -0.25, 4 * 0.33 / root_n + 1e-3);
  EXPECT_NEAR(2 * k / std::abs(w), 1.0, 4 * 0.8 / root_n);
}

// Hernquist in structural units (G = M = a = 1): the radius holding mass fraction m,
// and the isotropic velocity dispersion from the Jeans equation,
//   σ²(r) = (1/ρ) ∫_r^∞ ρ M/s² ds = r (1 + r)³ ∫_r^∞ ds / (s (1 + s)⁵)
//         = r (1 + r)³ [ln((1 + r)/r) − Σ_{k=2..5} (1 + r)^{1−k}/(k − 1)]
// (partial fractions; Hernquist 1990, eq. 10, in another form).
double hernquist_radius(double m) { return std::sqrt(m) / (1 - std::sqrt(m)); }
double hernquist_sigma2(double r) {
  double tail = std::log((1 + r) / r);
  for (int k = 2; k <= 5; ++k) tail -= std::pow(1 + r, 1 - k) / (k - 1);
  return r * std::pow(1 + r, 3) * tail;
}
constexpr double kHernquistCut = 0.99;  // HernquistOptions' default mass cut

TYPED_TEST(InitialConditionsTest, HernquistMassWithinFiveRadiiFollowsTheProfile) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const double a = 0.5;
  const ParticleSet<Real> p = hernquist<Real>(n, 7, {.scale_radius = a});
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = norm(p.position.get(i).template cast<double>());
  std::sort(r.begin(), r.end());
  // At 5 radii, 0.2 a to 10 a: the fraction of the particles inside, M(r)/M = r²/(r + a)² of the whole
  // model, over the cut (the particles are the inner kHernquistCut of it); binomial σ.
  for (double x : {0.2, 0.5, 1.0, 3.0, 10.0}) {
    const double expected = x * x / ((x + 1) * (x + 1)) / kHernquistCut;
    const double inside = double(std::upper_bound(r.begin(), r.end(), x * a) - r.begin()) / n;
    EXPECT_NEAR(inside, expected, 4 * std::sqrt(expected * (1 - expected) / n)) << "r = " << x << " a";
  }
  EXPECT_LT(r.back(), 1.01 * a * hernquist_radius(kHernquistCut));  // nothing beyond the cut (199 a)
}

TYPED_TEST(InitialConditionsTest, HernquistVelocitiesFollowTheJeansDispersionAndTheVirialTheorem) {
  using Real = TypeParam;
  // The mean ½v² at each mass coordinate is (3/2)σ²(r(m)): over the particles,
  // K = (1/(cut·a)) ∫₀^cut (3/2) σ²(r(m)) dm in units with a (velocities ∝ a^{−1/2}).
  const double a = 1.0 / 3.0;
  const double k_expected =
      integrate([](double m) { return 1.5 * hernquist_sigma2(hernquist_radius(m)); }, kHernquistCut) /
      (kHernquistCut * a);
  EXPECT_NEAR(k_expected, 0.25, 0.01);  // 1/4 for the whole model; the cut removes a little
  {
    constexpr std::size_t n = 65536;
    const ParticleSet<Real> p = hernquist<Real>(n, 8);
    double k = 0, k2 = 0, mass = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d v = p.velocity.get(i).template cast<double>();
      const double e = 0.5 * dot(v, v);
      k += p.mass[i] * e;
      k2 += e * e;
      mass += p.mass[i];
    }
    EXPECT_NEAR(mass, 1.0, 1e-5);
    const double sd = std::sqrt(k2 / n - k * k);
    EXPECT_NEAR(k, k_expected, 4 * sd / std::sqrt(double(n)));
    // Shell by shell, inside and outside a: ⟨v²⟩ = 3σ²(r), within 4 standard errors.
    for (const auto& [lo, hi] : {std::pair{0.1, 0.2}, std::pair{0.5, 0.6}, std::pair{2.0, 3.0}}) {
      double sum = 0, sum2 = 0, model = 0;
      std::size_t count = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const double r = norm(p.position.get(i).template cast<double>()) / a;
        if (r < lo || r >= hi) continue;
        const Vec3d v = p.velocity.get(i).template cast<double>();
        const double v2 = dot(v, v) * a;  // structural units
        sum += v2;
        sum2 += v2 * v2;
        model += 3 * hernquist_sigma2(r);
        ++count;
      }
      ASSERT_GT(count, 500u);
      const double mean = sum / double(count), sd_shell = std::sqrt(sum2 / double(count) - mean * mean);
      EXPECT_NEAR(mean, model / double(count), 4 * sd_shell / std::sqrt(double(count))) << "shell " << lo << " a";
    }
  }
  // W of the cut model, masses renormalised: −(1/(cut² a)) ∫₀^cut m/r(m) dm, m/r = √m (1 − √m),
  // × (1 − 1/N) for N(N−1) pairs; −1/2 for the whole model at a = 1/3.
  constexpr std::size_t n = 4096;
  const ParticleSet<Real> p = hernquist<Real>(n, 9);
  const double w_expected = -integrate([](double m) { return std::sqrt(m) * (1 - std::sqrt(m)); }, kHernquistCut) /
                            (kHernquistCut * kHernquistCut * a) * (1 - 1.0 / n);
  double k = 0;
  for (std::size_t i = 0; i < n; ++i)
    k += 0.5 * double(p.mass[i]) * dot(p.velocity.get(i).template cast<double>(), p.velocity.get(i).template cast<double>());
  const double w = potential_energy_exact(p);
  // Sampling spread, measured over 40 halos (N = 4096, seeds 1-40, direct sum without softening):
  // σ_W ≈ 0.78/√N and σ(2K/|W|) ≈ 1.34/√N, more than the Plummer sphere's (the cusp's close pairs);
  // their mean W = −0.514 ± 0.002 (−0.510 expected) and 2K/|W| = 0.987 ± 0.003 (0.990 expected).
  const double root_n = std::sqrt(double(n));
  EXPECT_NEAR(w, w_expected, 4 * 0.8 / root_n);
  EXPECT_NEAR(2 * k / std::abs(w), 2 * k_expected / std::abs(w_expected), 4 * 1.35 / root_n);
}

TYPED_TEST(InitialConditionsTest, ColdCollapseHasPotentialEnergyMinusThreeFifths) {
  using Real = TypeParam;
  constexpr std::size_t n = 4096;
  const ParticleSet<Real> p = cold_collapse<Real>(n, 4);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_LE(norm(p.position.get(i).template cast<double>()), 1.0 + 1e-6);
    ASSERT_EQ(p.velocity.get(i), Vec3<Real>{});
  }
  // W = −3GM²/5R for the continuum; N(N−1) pairs: × (1 − 1/N). σ_W ≈ 0.12/√N
  // (measured over 400 spheres of 1024 and 40 of 4096).
  EXPECT_NEAR(potential_energy_exact(p), -0.6 * (1 - 1.0 / n), 4 * 0.12 / std::sqrt(double(n)));
}

TYPED_TEST(InitialConditionsTest, UniformCubeAndSphereFillTheirVolumes) {
  using Real = TypeParam;
  constexpr std::size_t n = 20000;
  const double side = 2.0, radius = 3.0;
  const ParticleSet<Real> cube = uniform_cube<Real>(n, 5, side, 4.0);
  const ParticleSet<Real> sphere = uniform_sphere<Real>(n, 6, radius, 4.0);
  Vec3d mean{};
  double second = 0, mass = 0;
  std::size_t inner = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d x = cube.position.get(i).template cast<double>();
    for (int a = 0; a < 3; ++a) ASSERT_LE(std::abs(x[a]), side / 2);
    mean += x * (1.0 / n);
    second += x.x * x.x / n;
    mass += cube.mass[i];
    const double r = norm(sphere.position.get(i).template cast<double>());
    ASSERT_LE(r, radius * (1 + 1e-6));
    inner += r < radius / 2;
  }
  EXPECT_NEAR(mass, 4.0, 1e-4);
  // Uniform on [−L/2, L/2]: variance L²/12 per axis, σ of the mean L/sqrt(12N).
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(mean[a], 0.0, 4 * side / std::sqrt(12.0 * n));
  EXPECT_NEAR(second, side * side / 12, 4 * side * side / std::sqrt(180.0 * n));  // sd(x²) = L²/sqrt(180)
  // A ball of half the radius holds 1/8 of the volume: binomial σ.
  EXPECT_NEAR(double(inner) / n, 0.125, 4 * std::sqrt(0.125 * 0.875 / n));
}

TYPED_TEST(InitialConditionsTest, TwoPlummerSpheresStartOnTheCollisionOrbit) {
  using Real = TypeParam;
  constexpr std::size_t n = 3000;
  CollisionOptions o;
  o.mass_fraction = 0.25;
  const ParticleSet<Real> p = plummer_collision<Real>(n, 7, o);
  const std::size_t n1 = 750;
  std::array<double, 2> mass{};
  std::array<Vec3d, 2> x{}, v{};
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = i < n1 ? 0 : 1;
    mass[k] += p.mass[i];
    x[k] += double(p.mass[i]) * p.position.get(i).template cast<double>();
    v[k] += double(p.mass[i]) * p.velocity.get(i).template cast<double>();
    EXPECT_EQ(p.id[i], i);
  }
  EXPECT_NEAR(mass[0], 0.25, 1e-5);
  EXPECT_NEAR(mass[1], 0.75, 1e-5);
  // The pair's centre of mass is at rest at the origin.
  EXPECT_LT(norm(x[0] + x[1]), 1e-4);
  EXPECT_LT(norm(v[0] + v[1]), 1e-5);
  // r₂ − r₁ = (√(d² − b²), b, 0), v₂ − v₁ = (−√(2M/d), 0, 0) (parabolic), d = 10, b = 2.
  const Vec3d dx = x[1] * (1 / mass[1]) - x[0] * (1 / mass[0]);
  const Vec3d dv = v[1] * (1 / mass[1]) - v[0] * (1 / mass[0]);
  EXPECT_NEAR(dx.x, std::sqrt(96.0), 1e-4);
  EXPECT_NEAR(dx.y, 2.0, 1e-4);
  EXPECT_NEAR(dx.z, 0.0, 1e-4);
  EXPECT_NEAR(dv.x, -std::sqrt(0.2), 1e-5);
  EXPECT_NEAR(dv.y, 0.0, 1e-5);
  // Each sphere is scaled to length M_k^{1/3}: its half-mass radius is 0.7686·M_k^{1/3}.
  std::vector<double> r;
  for (std::size_t i = n1; i < n; ++i) r.push_back(norm(p.position.get(i).template cast<double>() - x[1] * (1 / mass[1])));
  std::nth_element(r.begin(), r.begin() + std::ptrdiff_t(r.size() / 2), r.end());
  EXPECT_NEAR(r[r.size() / 2], 0.7686 * std::cbrt(0.75), 0.1);
}

TYPED_TEST(InitialConditionsTest, SeedsReproduceAndDistinguish) {
  using Real = TypeParam;
  const auto check = [](const ParticleSet<Real>& a, const ParticleSet<Real>& b, const ParticleSet<Real>& c) {
    EXPECT_TRUE(testing::same_bits(a, b));
    EXPECT_FALSE(testing::same_bits(a, c));
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.id[i], i);
  };
  check(plummer<Real>(300, 9), plummer<Real>(300, 9), plummer<Real>(300, 10));
  check(uniform_sphere<Real>(300, 9), uniform_sphere<Real>(300, 9), uniform_sphere<Real>(300, 10));
  check(uniform_cube<Real>(300, 9), uniform_cube<Real>(300, 9), uniform_cube<Real>(300, 10));
  check(cold_collapse<Real>(300, 9), cold_collapse<Real>(300, 9), cold_collapse<Real>(300, 10));
  check(plummer_collision<Real>(300, 9), plummer_collision<Real>(300, 9), plummer_collision<Real>(300, 10));
}

}  // namespace
}  // namespace swirl::gravity
