// The disk galaxy (gravity/disk_galaxy.hpp) against closed forms computed
// here and against its own particles' gravity, within sampling error: 4
// standard deviations, as in initial_conditions_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/disk_galaxy.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class DiskGalaxyTest : public ::testing::Test {};
TYPED_TEST_SUITE(DiskGalaxyTest, testing::Precisions);

constexpr double kPi = std::numbers::pi;
const DiskGalaxyOptions kDefaults{};

// The fraction of an exponential disk's mass inside x = R/h.
double disk_fraction(double x) { return 1 - (1 + x) * std::exp(-x); }

// The midplane circular speed² of the model: Hernquist halo M_h R/(R + a)² and
// the razor-thin exponential disk, 2(M_d/h) y² [I₀K₀ − I₁K₁](y), y = R/2h
// (Freeman 1970; Binney & Tremaine 2008, eq. 2.165).
double model_v2(double r, const DiskGalaxyOptions& o) {
  const double y = r / (2 * o.disk_scale_length), mh = 1 - o.disk_mass, a = o.halo_scale_radius;
  const double bessel = std::cyl_bessel_i(0.0, y) * std::cyl_bessel_k(0.0, y) -
                        std::cyl_bessel_i(1.0, y) * std::cyl_bessel_k(1.0, y);
  return mh * r / ((r + a) * (r + a)) + 2 * o.disk_mass / o.disk_scale_length * y * y * bessel;
}

struct Split {
  std::size_t halo, disk;
};
Split split(std::size_t n, const DiskGalaxyOptions& o = kDefaults) {
  const auto disk = std::size_t(std::llround(o.disk_particles * double(n)));
  return {n - disk, disk};
}

TYPED_TEST(DiskGalaxyTest, SurfaceDensityVerticalProfileAndHaloMassFollowTheModel) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const DiskGalaxyOptions& o = kDefaults;
  const ParticleSet<Real> p = disk_galaxy<Real>(n, 31);
  const Split s = split(n);
  std::vector<double> radius, height, halo;
  double disk_mass = 0, halo_mass = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d x = p.position.get(i).template cast<double>();
    if (i < s.halo) {
      halo.push_back(norm(x));
      halo_mass += p.mass[i];
    } else {
      radius.push_back(std::hypot(x.x, x.y));
      height.push_back(std::abs(x.z));
      disk_mass += p.mass[i];
    }
  }
  EXPECT_NEAR(disk_mass, o.disk_mass, 1e-5);
  EXPECT_NEAR(halo_mass, (1 - o.disk_mass) * o.halo_mass_cut, 1e-5);
  std::sort(radius.begin(), radius.end());
  std::sort(height.begin(), height.end());
  std::sort(halo.begin(), halo.end());
  const auto fraction_below = [](const std::vector<double>& v, double x) {
    return double(std::upper_bound(v.begin(), v.end(), x) - v.begin()) / double(v.size());
  };
  const auto binomial = [](double f, std::size_t count) { return 4 * std::sqrt(f * (1 - f) / double(count)); };
  // Surface density: the fraction inside R = x h is that of the exponential disk cut at disk_cut·h.
  for (double x : {0.5, 1.0, 2.0, 3.0, 5.0}) {
    const double expected = disk_fraction(x) / disk_fraction(o.disk_cut);
    EXPECT_NEAR(fraction_below(radius, x * o.disk_scale_length), expected, binomial(expected, s.disk)) << "R = " << x << " h";
  }
  EXPECT_LE(radius.back(), o.disk_cut * o.disk_scale_length * (1 + 1e-6));
  // sech²(z/z₀): the fraction within |z| < k z₀ is tanh(k).
  for (double k : {0.5, 1.0, 2.0}) {
    const double expected = std::tanh(k);
    EXPECT_NEAR(fraction_below(height, k * o.disk_scale_height), expected, binomial(expected, s.disk)) << "|z| < " << k << " z0";
  }
  // The halo: M(r)/M = r²/(r + a)² over the cut, at 5 radii.
  for (double x : {0.1, 0.3, 1.0, 3.0, 10.0}) {
    const double expected = x * x / ((x + 1) * (x + 1)) / o.halo_mass_cut;
    EXPECT_NEAR(fraction_below(halo, x * o.halo_scale_radius), expected, binomial(expected, s.halo)) << "r = " << x << " a";
  }
}

// Annuli of the disk, R in [lo, hi) scale lengths.
constexpr std::pair<double, double> kAnnuli[] = {{0.4, 0.6}, {0.9, 1.1}, {1.8, 2.2}, {2.7, 3.3}, {3.6, 4.4}};

TYPED_TEST(DiskGalaxyTest, VelocitiesFollowTheEpicyclicMoments) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const DiskGalaxyOptions& o = kDefaults;
  const ParticleSet<Real> p = disk_galaxy<Real>(n, 32);
  const Split s = split(n);
  // Toomre's Q is the asked one at 2.43 h, and V_c is the closed form.
  const DiskKinematics ref = disk_kinematics({2.43 * o.disk_scale_length})[0];
  EXPECT_NEAR(ref.sigma_r * ref.epicyclic / (3.36 * ref.surface_density), o.toomre_q, 1e-9);
  // A razor-thin disk's V_c is Freeman's closed form (the Hankel quadrature's error ~10⁻⁴).
  DiskGalaxyOptions thin = o;
  thin.disk_scale_height = 1e-5;
  const std::vector<double> probe{0.05, 0.2, 0.5, 1.0, 1.9};
  const std::vector<DiskKinematics> k_thin = disk_kinematics(probe, thin);
  for (std::size_t j = 0; j < probe.size(); ++j)
    EXPECT_NEAR(k_thin[j].circular_speed * k_thin[j].circular_speed / model_v2(probe[j], o), 1.0, 2e-4) << "R = " << probe[j];
  std::vector<double> radii;
  for (std::size_t i = s.halo; i < n; ++i) radii.push_back(std::hypot(p.position.x[i], p.position.y[i]));
  const std::vector<DiskKinematics> model = disk_kinematics(radii);
  for (const auto& [lo, hi] : kAnnuli) {
    // Per particle: v_φ − v̄_φ(R), v_R²/σ_R² and v_z²/σ_z², each with mean 0, 1, 1 and its own spread.
    double sum[3] = {}, sum2[3] = {};
    std::size_t count = 0;
    for (std::size_t i = s.halo; i < n; ++i) {
      const Vec3d x = p.position.get(i).template cast<double>(), v = p.velocity.get(i).template cast<double>();
      const double r = std::hypot(x.x, x.y);
      if (r < lo * o.disk_scale_length || r >= hi * o.disk_scale_length) continue;
      const DiskKinematics& k = model[i - s.halo];
      const double vr = (x.x * v.x + x.y * v.y) / r, vphi = (x.x * v.y - x.y * v.x) / r;
      const double t[3] = {vphi - k.mean_rotation, vr * vr / (k.sigma_r * k.sigma_r), v.z * v.z / (k.sigma_z * k.sigma_z)};
      for (int a = 0; a < 3; ++a) sum[a] += t[a], sum2[a] += t[a] * t[a];
      ++count;
    }
    ASSERT_GT(count, 500u);
    const double expected[3] = {0, 1, 1};
    const char* what[3] = {"mean v_phi", "<v_R^2>", "<v_z^2>"};
    for (int a = 0; a < 3; ++a) {
      const double mean = sum[a] / double(count), sd = std::sqrt(sum2[a] / double(count) - mean * mean);
      EXPECT_NEAR(mean, expected[a], 4 * sd / std::sqrt(double(count))) << what[a] << " at R = " << lo << " h";
    }
  }
}

// The rotation curve: the circular speed the particles' own gravity gives,
// R·a_R (direct sum, softened by z₀/20) at the disk particles of an annulus
// near the midplane (|z| < z₀/4), against the model's V_c² — the disk's part
// from disk_kinematics() (the sech² disk's midplane field), the halo's from
// the sample's own enclosed halo mass M_h(<r)/r, since the halo's Poisson
// noise (±8 % of V_c² at 0.4 h, ±2 % at 2 h, for 16 384 halo particles) would
// swamp the disk's part. The residual per particle is the disk's
// discreteness and the halo's non-spherical noise; the mean within 4 of its
// standard errors (pulls measured within ±1.7). The razor-thin disk's V_c
// (Freeman) would be 5.7 standard errors off at h; the mean rotation v̄_φ is V_c
// less the asymmetric drift, 1–3 % of it here. And in the limit z₀ → 0 the
// model's V_c is Freeman's, to 2·10⁻⁴ (the Hankel integral's accuracy).
// In double only: the float sample differs by rounding, and the direct sum
// over 32 768 particles is the dearest part of this file.
TEST(DiskGalaxy, RotationCurveFollowsTheCircularSpeed) {
  using Real = double;
  constexpr std::size_t n = 32768;
  const DiskGalaxyOptions& o = kDefaults;
  const ParticleSet<double> p = testing::to_double(disk_galaxy<Real>(n, 33));
  GravityField<double> f;
  direct_sum(p, o.disk_scale_height / 20, 128, f);
  const Split s = split(n);
  std::vector<double> halo(s.halo), radii;
  for (std::size_t i = 0; i < s.halo; ++i) halo[i] = norm(p.position.get(i));
  std::sort(halo.begin(), halo.end());
  const double halo_particle = p.mass[0];
  for (std::size_t i = s.halo; i < n; ++i) radii.push_back(std::hypot(p.position.x[i], p.position.y[i]));
  const std::vector<DiskKinematics> kin = disk_kinematics(radii);
  const double mh = 1 - o.disk_mass, a = o.halo_scale_radius;
  for (const auto& [lo, hi] : kAnnuli) {
    double sum = 0, sum2 = 0, rotation = 0, circular = 0;
    std::size_t count = 0;
    for (std::size_t i = s.halo; i < n; ++i) {
      const Vec3d x = p.position.get(i);
      const double r = radii[i - s.halo], sph = norm(x);
      if (r < lo * o.disk_scale_length || r >= hi * o.disk_scale_length || std::abs(x.z) > 0.25 * o.disk_scale_height)
        continue;
      const DiskKinematics& k = kin[i - s.halo];
      const double measured = -(x.x * f.acceleration[0][i] + x.y * f.acceleration[1][i]);  // R·a_R, inward
      const double halo_model = mh * r / ((r + a) * (r + a));
      const double disk_v2 = k.circular_speed * k.circular_speed - halo_model;
      const double halo_sample =
          halo_particle * double(std::upper_bound(halo.begin(), halo.end(), sph) - halo.begin()) * r * r / (sph * sph * sph);
      const double residual = measured / (halo_sample + disk_v2) - 1;
      sum += residual;
      sum2 += residual * residual;
      rotation += k.mean_rotation;
      circular += k.circular_speed;
      ++count;
    }
    ASSERT_GT(count, 200u);
    const double mean = sum / double(count), se = std::sqrt(sum2 / double(count) - mean * mean) / std::sqrt(double(count));
    EXPECT_NEAR(mean, 0.0, 4 * se) << "R = " << lo << " h";
    // The asymmetric drift is a small correction to V_c where the epicyclic approximation holds (R ≥ h).
    if (lo >= 0.9) {
      EXPECT_LT(1 - rotation / circular, 0.05) << "R = " << lo << " h";
    }
  }
}

// The halo's velocities: ⟨v²⟩ in shells against 3σ² of the isotropic Jeans
// equation in the potential of halo and spherically averaged disk,
// σ²(r) = (1/ρ) ∫_r^∞ ρ (M_h(s) + M_d(<s)) / s² ds, by the trapezoidal rule in
// ln s (20 000 nodes from 10⁻³ a to 10⁴ a).
TYPED_TEST(DiskGalaxyTest, HaloFollowsTheJeansDispersionInTheTotalPotential) {
  using Real = TypeParam;
  constexpr std::size_t n = 65536;
  const DiskGalaxyOptions& o = kDefaults;
  const double a = o.halo_scale_radius, mh = 1 - o.disk_mass, h = o.disk_scale_length;
  const auto rho = [&](double r) { return mh * a / (2 * kPi * r * std::pow(r + a, 3)); };
  const auto mass = [&](double r) { return mh * r * r / ((r + a) * (r + a)) + o.disk_mass * disk_fraction(r / h); };
  // σ² on the nodes, the integral accumulated from the outermost node in, linear in ln r between.
  constexpr int nodes = 20000;
  const double lo_r = std::log(1e-3 * a), hi_r = std::log(1e4 * a), step = (hi_r - lo_r) / nodes;
  std::vector<double> table(nodes + 1);
  double outer = 0;
  for (int k = nodes; k >= 0; --k) {
    const double s1 = std::exp(lo_r + step * k), s2 = std::exp(lo_r + step * (k + 1));
    if (k < nodes) outer += 0.5 * step * (rho(s1) * mass(s1) / s1 + rho(s2) * mass(s2) / s2);  // ds = s d(ln s)
    table[std::size_t(k)] = outer / rho(s1);
  }
  const auto sigma2 = [&](double r) {
    const double u = (std::log(r) - lo_r) / step;
    const auto k = std::size_t(std::clamp(u, 0.0, double(nodes - 1)));
    return table[k] + (u - double(k)) * (table[k + 1] - table[k]);
  };
  const ParticleSet<Real> p = disk_galaxy<Real>(n, 34);
  const Split s = split(n);
  for (const auto& [lo, hi] : {std::pair{0.1, 0.2}, std::pair{0.3, 0.4}, std::pair{0.8, 1.2}, std::pair{3.0, 5.0}}) {
    double sum = 0, sum2 = 0, expected = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < s.halo; ++i) {
      const double r = norm(p.position.get(i).template cast<double>());
      if (r < lo * a || r >= hi * a) continue;
      const Vec3d v = p.velocity.get(i).template cast<double>();
      sum += dot(v, v);
      sum2 += dot(v, v) * dot(v, v);
      expected += 3 * sigma2(r);
      ++count;
    }
    ASSERT_GT(count, 300u);
    const double mean = sum / double(count), sd = std::sqrt(sum2 / double(count) - mean * mean);
    EXPECT_NEAR(mean, expected / double(count), 4 * sd / std::sqrt(double(count))) << "shell " << lo << " a";
  }
}

TYPED_TEST(DiskGalaxyTest, GalaxyIsCloseToVirialEquilibrium) {
  using Real = TypeParam;
  constexpr std::size_t n = 4096;
  const ParticleSet<double> p = testing::to_double(disk_galaxy<Real>(n, 35));
  GravityField<double> f;
  direct_sum(p, 0.0, 128, f);
  double k = 0, w = 0;
  Vec3d mv{};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d v = p.velocity.get(i);
    k += 0.5 * p.mass[i] * dot(v, v);
    w += 0.5 * p.mass[i] * f.potential[i];
    mv += p.mass[i] * v;
  }
  EXPECT_LT(norm(mv), 1e-6);
  // Over 40 galaxies (N = 4096, seeds 1-40, unsoftened direct sum): 2K/|W| = 1.0012 ± 0.0043
  // (the disk's Jeans moments and the halo's distribution function together), spread
  // σ(2K/|W|) ≈ 1.72/√N, larger than a halo's alone (the disk's cold, close pairs).
  EXPECT_NEAR(2 * k / std::abs(w), 1.0, 4 * 1.72 / std::sqrt(double(n)));
}

TEST(DiskGalaxy, RejectsParametersOutOfRange) {
  const auto message = [](const DiskGalaxyOptions& o, std::size_t n = 100) {
    try {
      (void)disk_galaxy<double>(n, 1, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({.disk_mass = 1}), "disk_galaxy: disk_mass = 1 must be in (0, 1)");
  EXPECT_EQ(message({.disk_scale_height = 0}), "disk_galaxy: disk_scale_height = 0 must be finite and > 0");
  EXPECT_EQ(message({.disk_cut = 60}), "disk_galaxy: disk_cut = 60 must be in [2, 50]");
  EXPECT_EQ(message({.toomre_q = -1}), "disk_galaxy: toomre_q = -1 must be finite and > 0");
  EXPECT_EQ(message({}, 1),
            "disk_galaxy: 1 particles cannot be split 0.5 : 0.5 with at least one each in the disk and the halo");
  EXPECT_THROW((void)disk_kinematics({0.0}), std::invalid_argument);
}

TYPED_TEST(DiskGalaxyTest, SeedsReproduceAndDistinguish) {
  using Real = TypeParam;
  const ParticleSet<Real> a = disk_galaxy<Real>(300, 9), b = disk_galaxy<Real>(300, 9), c = disk_galaxy<Real>(300, 10);
  EXPECT_TRUE(testing::same_bits(a, b));
  EXPECT_FALSE(testing::same_bits(a, c));
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.id[i], i);
}

}  // namespace
}  // namespace swirl::gravity
