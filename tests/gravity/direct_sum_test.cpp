// The exact reference: direct summation with Plummer softening.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class DirectSumTest : public ::testing::Test {};
TYPED_TEST_SUITE(DirectSumTest, testing::Precisions);

TYPED_TEST(DirectSumTest, ThreeBodiesMatchTheSoftenedNewtonLaw) {
  using Real = TypeParam;
  ParticleSet<Real> p(3);
  p.position.set(0, {0, 0, 0});
  p.position.set(1, {Real(3), 0, 0});
  p.position.set(2, {0, Real(4), 0});
  p.mass[0] = 1;
  p.mass[1] = 2;
  p.mass[2] = 5;
  const double eps = 0.5;
  GravityField<Real> f;
  direct_sum(p, Real(eps), 2, f);
  // a_0 = Σ m_j r_j / (|r_j|² + ε²)^{3/2}, φ_0 = −Σ m_j / sqrt(|r_j|² + ε²)
  const double d1 = 9 + eps * eps, d2 = 16 + eps * eps;
  const double tol = 8 * std::numeric_limits<Real>::epsilon();
  EXPECT_NEAR(f.acceleration.x[0], 2 * 3 / std::pow(d1, 1.5), tol);
  EXPECT_NEAR(f.acceleration.y[0], 5 * 4 / std::pow(d2, 1.5), tol);
  EXPECT_EQ(f.acceleration.z[0], Real(0));
  EXPECT_NEAR(f.potential[0], -2 / std::sqrt(d1) - 5 / std::sqrt(d2), tol);
  // Particle 1 feels particle 0 along −x and particle 2 along (−3, 4)/5 at distance 5.
  const double d12 = 25 + eps * eps;
  EXPECT_NEAR(f.acceleration.x[1], -1 * 3 / std::pow(d1, 1.5) - 5 * 3 / std::pow(d12, 1.5), tol);
  EXPECT_NEAR(f.acceleration.y[1], 5 * 4 / std::pow(d12, 1.5), tol);
}

TYPED_TEST(DirectSumTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(1500, 1);
  const int saved = parallel::thread_count();
  GravityField<Real> one, other;
  parallel::set_thread_count(1);
  direct_sum(p, Real(0.01), 64, one);
  for (int threads : {2, 3}) {
    parallel::set_thread_count(threads);
    direct_sum(p, Real(0.01), 64, other);
    EXPECT_TRUE(testing::same_bits(one, other));
  }
  parallel::set_thread_count(saved);
}

template <class Real>
Vec3d momentum(const ParticleSet<Real>& p) {
  Vec3d m{};
  for (std::size_t i = 0; i < p.size(); ++i) m += double(p.mass[i]) * p.velocity.get(i).template cast<double>();
  return m;
}

// Largest change of Σ m v over `steps` leapfrog steps.
template <class Real>
double momentum_drift(const ParticleSet<Real>& initial, const GravitySettings& g, double dt, int steps) {
  SimulationSettings ss;
  ss.dt = dt;
  ss.block_size = 128;
  Simulation<Real> sim(initial, ss);
  sim.add_solver(std::make_unique<GravityForce<Real>>(g));
  sim.start();
  const Vec3d p0 = momentum(sim.particles());
  double drift = 0;
  for (int s = 0; s < steps; ++s) {
    sim.step();
    drift = std::max(drift, norm(momentum(sim.particles()) - p0));
  }
  return drift;
}

TYPED_TEST(DirectSumTest, IntegrationConservesLinearMomentumToRoundOff) {
  using Real = TypeParam;
  constexpr std::size_t n = 512;
  constexpr double dt = 1.0 / 64, eps = 0.05;
  constexpr int steps = 200;
  const ParticleSet<Real> p = plummer<Real>(n, 17);
  // Pair forces are equal and opposite, so Σ m a = 0 but for rounding. Each
  // a_i is a sum of N terms, off by ~u·√N·S_i (S_i = Σ_j |term|), and each
  // kick rounds v_i by ~u·|v_i|; these errors have random signs, so per step
  // Σ m v moves by ~u·(sqrt(Σ m²|v|²) + Δt·√N·sqrt(Σ m² S²)), and over the
  // steps it walks randomly: × √steps. Tolerance: 8 times that.
  const double u = std::numeric_limits<Real>::epsilon() / 2;
  double m2v2 = 0, m2s2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d xi = p.position.get(i).template cast<double>();
    double s = 0;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const double r = norm(p.position.get(j).template cast<double>() - xi);
      s += double(p.mass[j]) * r / std::pow(r * r + eps * eps, 1.5);
    }
    const double m = p.mass[i];
    m2v2 += m * m * dot(p.velocity.get(i).template cast<double>(), p.velocity.get(i).template cast<double>());
    m2s2 += m * m * s * s;
  }
  const double tol = 8 * u * std::sqrt(double(steps)) * (std::sqrt(m2v2) + dt * std::sqrt(double(n) * m2s2));
  GravitySettings g;
  g.method = Method::Direct;
  g.softening = eps;
  // 512 particles need no threads (and a busy machine makes many small parallel loops slow).
  const int saved = parallel::thread_count();
  parallel::set_thread_count(1);
  EXPECT_LT(momentum_drift(p, g, dt, steps), tol);
  // A tree's forces are not pairwise symmetric: its momentum error is far
  // larger, which shows the bound can tell.
  g.method = Method::BarnesHut;
  g.opening = 0.7;
  EXPECT_GT(momentum_drift(p, g, dt, steps), 10 * tol);
  parallel::set_thread_count(saved);
}

}  // namespace
}  // namespace swirl::gravity
