// The NFW and King models (gravity/spherical_models.hpp) against profiles
// computed here independently of the library's tables (closed forms, a
// separate ODE solution and separate quadratures), within sampling error: 4
// standard deviations, as in initial_conditions_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/spherical_models.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class SphericalModelsTest : public ::testing::Test {};
TYPED_TEST_SUITE(SphericalModelsTest, testing::Precisions);

constexpr double kPi = std::numbers::pi;

template <class Real>
std::vector<double> sorted_radii(const ParticleSet<Real>& p) {
  std::vector<double> r(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) r[i] = norm(p.position.get(i).template cast<double>());
  std::sort(r.begin(), r.end());
  return r;
}

template <class Real>
double potential_energy_exact(const ParticleSet<Real>& p) {
  GravityField<double> f;
  const ParticleSet<double> d = testing::to_double(p);
  direct_sum(d, 0.0, 128, f);
  double w = 0;
  for (std::size_t i = 0; i < d.size(); ++i) w += 0.5 * d.mass[i] * f.potential[i];
  return w;
}

template <class Real>
double kinetic_energy(const ParticleSet<Real>& p) {
  double k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3d v = p.velocity.get(i).template cast<double>();
    k += 0.5 * double(p.mass[i]) * dot(v, v);
  }
  return k;
}

// A profile on a fine logarithmic grid of radii (G = 1): density, enclosed
// mass and the isotropic Jeans dispersion σ²(r) = (1/ρ) ∫_r^∞ ρ M/s² ds, each
// integral by the trapezoidal rule in ln s (20 000 nodes).
struct Profile {
  std::vector<double> r, rho, mass, sigma2;
  double at(const std::vector<double>& y, double x) const {
    const auto k = std::size_t(std::upper_bound(r.begin(), r.end(), x) - r.begin());
    if (k == 0) return y.front();
    if (k == r.size()) return y.back();
    const double t = std::log(x / r[k - 1]) / std::log(r[k] / r[k - 1]);
    return y[k - 1] + t * (y[k] - y[k - 1]);
  }
  void fill_jeans() {
    const std::size_t n = r.size();
    sigma2.assign(n, 0.0);
    double outer = 0;  // ∫ ρ M/s² ds = ∫ ρ M/s d(ln s)
    for (std::size_t k = n - 1; k-- > 0;) {
      outer += 0.5 * std::log(r[k + 1] / r[k]) * (rho[k + 1] * mass[k + 1] / r[k + 1] + rho[k] * mass[k] / r[k]);
      sigma2[k] = rho[k] > 0 ? outer / rho[k] : 0.0;
    }
  }
};

// ---- NFW ---------------------------------------------------------------------

// The NFW halo of NfwOptions{c, decay} in units r_s = 1, ρ = 1/(x (1 + x)²)
// inside c: mass 4π [ln(1 + x) − x/(1 + x)] there, the Kazantzidis et al.
// (2004) tail ρ(c)(x/c)^κ e^{−(x − c)/x_d} integrated numerically beyond.
Profile nfw_profile(double c, double decay) {
  const double xd = decay * c, kappa = -(1 + 3 * c) / (1 + c) + 1 / decay;
  const auto rho = [&](double x) {
    return x <= c ? 1 / (x * (1 + x) * (1 + x)) : std::pow(x / c, kappa) * std::exp(-(x - c) / xd) / (c * (1 + c) * (1 + c));
  };
  Profile p;
  const double lo = std::log(1e-4), hi = std::log(c + 60 * xd);
  constexpr int n = 20000;
  for (int k = 0; k <= n; ++k) p.r.push_back(std::exp(lo + (hi - lo) * k / n));
  for (double x : p.r) p.rho.push_back(rho(x));
  for (std::size_t k = 0; k < p.r.size(); ++k) {
    const double x = p.r[k];
    if (x <= c) {
      p.mass.push_back(4 * kPi * (std::log(1 + x) - x / (1 + x)));
    } else {
      const double dlx = std::log(x / p.r[k - 1]);
      const double m0 = p.r[k - 1] <= c ? 4 * kPi * (std::log(1 + c) - c / (1 + c)) : p.mass[k - 1];
      const double x0 = std::max(p.r[k - 1], c);
      // The interval straddling c: only its part beyond c is tail.
      const double d = p.r[k - 1] <= c ? std::log(x / c) : dlx;
      p.mass.push_back(m0 + 0.5 * d * 4 * kPi * (x * x * x * p.rho[k] + x0 * x0 * x0 * rho(x0)));
    }
  }
  p.fill_jeans();
  return p;
}

TYPED_TEST(SphericalModelsTest, NfwMassWithinFiveRadiiFollowsTheTruncatedProfile) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const double c = 10, r_vir = 2;  // r_s = 0.2
  const Profile model = nfw_profile(c, 0.1);
  const double total = model.mass.back();
  const std::vector<double> r = sorted_radii(nfw<Real>(n, 11, {.concentration = c, .virial_radius = r_vir}));
  // At 0.3, 1 and 3 r_s, at r_vir and in the tail (1.5 r_vir): binomial σ.
  for (double x : {0.3, 1.0, 3.0, 10.0, 15.0}) {
    const double expected = model.at(model.mass, x) / total;
    const double inside = double(std::upper_bound(r.begin(), r.end(), x * r_vir / c) - r.begin()) / n;
    EXPECT_NEAR(inside, expected, 4 * std::sqrt(expected * (1 - expected) / n)) << "r = " << x << " r_s";
  }
  // The tail's (x/c)^κ (κ = 7.2 here) holds it out beyond r_vir + 20 r_d, but not 60 r_d.
  EXPECT_GT(r.back(), r_vir * (1 + 20 * 0.1));
  EXPECT_LT(r.back(), r_vir * (1 + 60 * 0.1));
}

TYPED_TEST(SphericalModelsTest, NfwVelocitiesFollowTheJeansDispersion) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const double c = 10, r_vir = 1;
  const Profile model = nfw_profile(c, 0.1);
  const ParticleSet<Real> p = nfw<Real>(n, 12, {.concentration = c, .virial_radius = r_vir});
  // Structural units (r_s = 1, mass model.mass.back()) → r_vir = 1, M = 1:
  // lengths × r_vir/c, v² × 1/(M_t · r_vir/c).
  const double length = r_vir / c, v2_unit = 1 / (model.mass.back() * length);
  // Shell by shell, from the cusp to the tail: ⟨v²⟩ = 3σ²(r), within 4 standard errors.
  for (const auto& [lo, hi] : {std::pair{0.1, 0.25}, std::pair{0.5, 0.7}, std::pair{2.0, 3.0}, std::pair{8.0, 10.0},
                               std::pair{10.0, 13.0}}) {
    double sum = 0, sum2 = 0, expected = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = norm(p.position.get(i).template cast<double>()) / length;
      if (x < lo || x >= hi) continue;
      const Vec3d v = p.velocity.get(i).template cast<double>();
      const double v2 = dot(v, v) / v2_unit;
      sum += v2;
      sum2 += v2 * v2;
      expected += 3 * model.at(model.sigma2, x);
      ++count;
    }
    ASSERT_GT(count, 400u) << "shell " << lo << " r_s";
    const double mean = sum / double(count), sd = std::sqrt(sum2 / double(count) - mean * mean);
    EXPECT_NEAR(mean, expected / double(count), 4 * sd / std::sqrt(double(count))) << "shell " << lo << " r_s";
  }
}

TYPED_TEST(SphericalModelsTest, NfwIsVirialisedInHenonUnits) {
  using Real = TypeParam;
  constexpr std::size_t n = 4096;
  const ParticleSet<Real> p = nfw<Real>(n, 13);
  double mass = 0;
  Vec3d mv{};
  for (std::size_t i = 0; i < n; ++i) {
    mass += p.mass[i];
    mv += double(p.mass[i]) * p.velocity.get(i).template cast<double>();
  }
  EXPECT_NEAR(mass, 1.0, 1e-5);
  EXPECT_LT(norm(mv), 1e-5);
  const double k = kinetic_energy(p), w = potential_energy_exact(p);
  // Sampling spread, measured over 40 halos (N = 4096, seeds 1-40, c = 10, unsoftened
  // direct sum): σ_W ≈ 0.44/√N, σ_E ≈ 0.42/√N, σ(2K/|W|) ≈ 1.08/√N; their means
  // W = −0.5006 ± 0.0011, E = −0.2502, 2K/|W| = 1.0006 ± 0.0026.
  const double root_n = std::sqrt(double(n));
  EXPECT_NEAR(w, -0.5 * (1 - 1.0 / n), 4 * 0.44 / root_n);
  EXPECT_NEAR(k + w, -0.25, 4 * 0.42 / root_n);
  EXPECT_NEAR(2 * k / std::abs(w), 1.0, 4 * 1.08 / root_n);
}

TEST(SphericalModels, NfwRejectsParametersOutOfRange) {
  const auto message = [](const NfwOptions& o) {
    try {
      (void)nfw<double>(10, 1, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({.concentration = 0.5}), "nfw: concentration = 0.5 must be in [1, 100]");
  EXPECT_EQ(message({.decay = 0}), "nfw: decay = 0 must be in [0.01, 1]");
  EXPECT_EQ(message({.virial_radius = -1.0}), "nfw: virial_radius = -1 must be finite and > 0");
  EXPECT_THROW((void)nfw<double>(0, 1), std::invalid_argument);
}

// ---- King --------------------------------------------------------------------

// The King model of central potential w0 in King units (r₀ = σ = G = 1) by
// classical RK4 in r (step 10⁻⁴, not the library's ln r), the density from
// erf: ρ(W)/ρ(W₀) with ρ(W) = e^W erf(√W) − √(4W/π)(1 + 2W/3); mass μ = −r² W′.
struct KingProfile {
  Profile p;
  std::vector<double> w;
  double tidal_radius = 0, potential_energy = 0;
};
KingProfile king_profile(double w0) {
  const auto rho = [](double w) {
    return w > 0 ? std::exp(w) * std::erf(std::sqrt(w)) - std::sqrt(4 * w / kPi) * (1 + 2 * w / 3) : 0.0;
  };
  const double rho0 = rho(w0), h = 1e-4;
  const auto accel = [&](double r, double w, double dw) { return -9 * rho(w) / rho0 - 2 * dw / r; };
  KingProfile k;
  double r = h, w = w0 - 1.5 * h * h, dw = -3 * h;
  const auto keep = [&] {
    k.p.r.push_back(r);
    k.w.push_back(w);
    k.p.rho.push_back(rho(w) / rho0);
    k.p.mass.push_back(-r * r * dw);
  };
  keep();
  while (true) {
    const double a1 = accel(r, w, dw);
    const double w2 = w + h / 2 * dw, d2 = dw + h / 2 * a1, a2 = accel(r + h / 2, w2, d2);
    const double w3 = w + h / 2 * d2, d3 = dw + h / 2 * a2, a3 = accel(r + h / 2, w3, d3);
    const double w4 = w + h * d3, d4 = dw + h * a3, a4 = accel(r + h, w4, d4);
    const double w_next = w + h / 6 * (dw + 2 * d2 + 2 * d3 + d4);
    const double dw_next = dw + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    if (w_next <= 0) {
      // The last fraction of a step, linearly: W′ barely changes over it.
      const double t = w / (w - w_next);
      r += t * h, dw += t * (dw_next - dw), w = 0;
      keep();
      break;
    }
    r += h, w = w_next, dw = dw_next;
    keep();
  }
  k.tidal_radius = r;
  k.p.fill_jeans();
  // W = −∫ μ dμ / r by the trapezoidal rule.
  for (std::size_t i = 1; i < k.p.r.size(); ++i)
    k.potential_energy -= 0.5 * (k.p.mass[i] - k.p.mass[i - 1]) *
                          (k.p.mass[i] / k.p.r[i] + k.p.mass[i - 1] / k.p.r[i - 1]);
  return k;
}

TYPED_TEST(SphericalModelsTest, KingMassWithinFiveRadiiFollowsThePoissonSolution) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  for (double w0 : {3.0, 6.0, 9.0}) {
    SCOPED_TRACE(w0);
    const KingProfile model = king_profile(w0);
    const double mu = model.p.mass.back();
    // Hénon units: M = μ_t → 1 and W → −1/2, so lengths × 2|W|/μ_t² (King radii → Hénon).
    const double length = 2 * std::abs(model.potential_energy) / (mu * mu);
    const KingScales scales = king_scales({.w0 = w0});
    EXPECT_NEAR(scales.king_radius / length, 1.0, 1e-4);
    EXPECT_NEAR(scales.tidal_radius / (model.tidal_radius * length), 1.0, 1e-4);
    // The known concentrations log₁₀(r_t/r₀): 0.67, 1.26 and 2.12 (King 1966's table, to two decimals).
    const double concentration = std::log10(model.tidal_radius);
    EXPECT_NEAR(concentration, w0 == 3.0 ? 0.67 : w0 == 6.0 ? 1.26 : 2.12, 0.01);
    const std::vector<double> r = sorted_radii(king<Real>(n, 21, {.w0 = w0}));
    EXPECT_LT(r.back(), scales.tidal_radius * 1.05);  // the centre of mass moves a little
    // At 0.5, 1, 3 King radii and at a quarter and half the tidal radius: binomial σ.
    for (double x : {0.5, 1.0, 3.0, 0.25 * model.tidal_radius, 0.5 * model.tidal_radius}) {
      const double expected = model.p.at(model.p.mass, x) / mu;
      const double inside = double(std::upper_bound(r.begin(), r.end(), x * length) - r.begin()) / n;
      EXPECT_NEAR(inside, expected, 4 * std::sqrt(expected * (1 - expected) / n)) << "r = " << x << " r0";
    }
  }
}

TYPED_TEST(SphericalModelsTest, KingVelocitiesFollowTheJeansDispersion) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const double w0 = 6;
  const KingProfile model = king_profile(w0);
  const double mu = model.p.mass.back();
  const double length = 2 * std::abs(model.potential_energy) / (mu * mu), v2_unit = 1 / (mu * length);
  const ParticleSet<Real> p = king<Real>(n, 22, {.w0 = w0});
  const double rt = model.tidal_radius;
  for (const auto& [lo, hi] : {std::pair{0.0, 0.5}, std::pair{1.0, 1.5}, std::pair{3.0, 4.0},
                               std::pair{0.4 * rt, 0.5 * rt}, std::pair{0.7 * rt, 0.9 * rt}}) {
    double sum = 0, sum2 = 0, expected = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = norm(p.position.get(i).template cast<double>()) / length;
      if (x < lo || x >= hi) continue;
      const Vec3d v = p.velocity.get(i).template cast<double>();
      const double v2 = dot(v, v) / v2_unit;
      sum += v2;
      sum2 += v2 * v2;
      expected += 3 * model.p.at(model.p.sigma2, x);
      ++count;
    }
    ASSERT_GT(count, 300u) << "shell " << lo << " r0";
    const double mean = sum / double(count), sd = std::sqrt(sum2 / double(count) - mean * mean);
    EXPECT_NEAR(mean, expected / double(count), 4 * sd / std::sqrt(double(count))) << "shell " << lo << " r0";
  }
}

TYPED_TEST(SphericalModelsTest, KingIsVirialisedInHenonUnits) {
  using Real = TypeParam;
  constexpr std::size_t n = 4096;
  const ParticleSet<Real> p = king<Real>(n, 23);
  double mass = 0;
  Vec3d mx{}, mv{};
  for (std::size_t i = 0; i < n; ++i) {
    mass += p.mass[i];
    mx += double(p.mass[i]) * p.position.get(i).template cast<double>();
    mv += double(p.mass[i]) * p.velocity.get(i).template cast<double>();
  }
  EXPECT_NEAR(mass, 1.0, 1e-5);
  EXPECT_LT(norm(mx), 1e-5);
  EXPECT_LT(norm(mv), 1e-5);
  const double k = kinetic_energy(p), w = potential_energy_exact(p);
  // Sampling spread, measured over 40 clusters (N = 4096, seeds 1-40, W₀ = 6, unsoftened
  // direct sum): σ_W ≈ 0.44/√N, σ_E ≈ 0.42/√N, σ(2K/|W|) ≈ 0.95/√N; their means
  // W = −0.5000 ± 0.0011, E = −0.2503, 2K/|W| = 0.9991 ± 0.0024.
  const double root_n = std::sqrt(double(n));
  EXPECT_NEAR(w, -0.5 * (1 - 1.0 / n), 4 * 0.44 / root_n);
  EXPECT_NEAR(k + w, -0.25, 4 * 0.42 / root_n);
  EXPECT_NEAR(2 * k / std::abs(w), 1.0, 4 * 0.95 / root_n);
}

TEST(SphericalModels, KingRejectsParametersOutOfRange) {
  try {
    (void)king<double>(10, 1, {.w0 = 20});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "king: w0 = 20 must be in [0.1, 16]");
  }
  EXPECT_THROW((void)king<double>(0, 1), std::invalid_argument);
  EXPECT_THROW((void)king_scales({.w0 = 0}), std::invalid_argument);
}

TYPED_TEST(SphericalModelsTest, SeedsReproduceAndDistinguish) {
  using Real = TypeParam;
  const auto check = [](const ParticleSet<Real>& a, const ParticleSet<Real>& b, const ParticleSet<Real>& c) {
    EXPECT_TRUE(testing::same_bits(a, b));
    EXPECT_FALSE(testing::same_bits(a, c));
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.id[i], i);
  };
  check(nfw<Real>(300, 9), nfw<Real>(300, 9), nfw<Real>(300, 10));
  check(king<Real>(300, 9), king<Real>(300, 9), king<Real>(300, 10));
}

}  // namespace
}  // namespace swirl::gravity
