// Individual (block) time steps (integrate/block_steps.hpp) and the active-set
// force evaluations they rest on (core/active_set.hpp): active-only forces
// against full ones, the stepper against the global leapfrog it generalises,
// a two-body orbit and a Plummer sphere against known answers, thread counts
// and resume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/integrate/block_steps.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class BlockStepsTest : public ::testing::Test {};
TYPED_TEST_SUITE(BlockStepsTest, testing::Precisions);

// Bins 0..3 scattered over the particles (a fixed pattern, no clustering).
std::vector<std::int32_t> scattered_bins(std::size_t n) {
  std::vector<std::int32_t> bins(n);
  for (std::size_t i = 0; i < n; ++i) bins[i] = std::int32_t((i * 7919u + i / 13) % 4);
  return bins;
}

template <class Real>
constexpr Real kSentinel = Real(12345);

template <class Real>
void fill(GravityField<Real>& f, std::size_t n, Real value) {
  f.resize(n);
  for (int a = 0; a < 3; ++a) std::fill(f.acceleration[a].begin(), f.acceleration[a].end(), value);
  std::fill(f.potential.begin(), f.potential.end(), value);
}

// Active particles' entries equal (bitwise, or within tol·|full|), the others untouched.
template <class Real>
void expect_active_entries(const GravityField<Real>& active, const GravityField<Real>& full, const ActiveSet& set,
                           double tol) {
  std::size_t computed = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (!set.contains(i)) {
      ASSERT_EQ(active.potential[i], kSentinel<Real>) << "inactive particle " << i << " was written";
      continue;
    }
    ++computed;
    const double scale = std::hypot(double(full.acceleration.x[i]), double(full.acceleration.y[i]),
                                    double(full.acceleration.z[i]));
    for (int a = 0; a < 3; ++a) {
      if (tol == 0)
        ASSERT_EQ(active.acceleration[a][i], full.acceleration[a][i]) << "particle " << i << " axis " << a;
      else
        ASSERT_LE(std::abs(double(active.acceleration[a][i]) - double(full.acceleration[a][i])), tol * scale)
            << "particle " << i << " axis " << a;
    }
    if (tol == 0)
      ASSERT_EQ(active.potential[i], full.potential[i]) << "particle " << i;
    else
      ASSERT_LE(std::abs(double(active.potential[i]) - double(full.potential[i])), tol * std::abs(double(full.potential[i])));
  }
  EXPECT_GT(computed, 0u);
}

template <class Real>
GravityField<Real> active_tree_field(const ParticleSet<Real>& p, const GravitySettings& s, const ActiveSet& set) {
  BarnesHut<Real> tree(s);
  GravityField<Real> f;
  fill(f, p.size(), kSentinel<Real>);
  tree.compute(p, f, 64, set);
  return f;
}

TYPED_TEST(BlockStepsTest, DirectSumAndParticleWalkOfTheActiveAreTheFullOnesBitForBit) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(1500, 3);
  const std::vector<std::int32_t> bins = scattered_bins(p.size());
  const ActiveSet set{bins.data(), 2};

  GravityField<Real> full, active;
  direct_sum(p, Real(0.01), 64, full);
  fill(active, p.size(), kSentinel<Real>);
  direct_sum(p, Real(0.01), 64, active, set);
  expect_active_entries(active, full, set, 0);

  GravitySettings s;
  s.walk = Walk::Particle;
  expect_active_entries(active_tree_field(p, s, set), testing::tree_field(p, s), set, 0);
}

TYPED_TEST(BlockStepsTest, GroupWalkOfTheActiveIsTheFullOneWithinTheOpeningError) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(3000, 5);
  const std::vector<std::int32_t> bins = scattered_bins(p.size());
  GravitySettings s;
  s.group_size = 64;  // many groups, most of them partly active

  // Every particle active through a set (min_bin 0 is "all"; min_bin 1 with
  // every bin >= 1 makes every group fully active): the full evaluation's bits.
  std::vector<std::int32_t> ones(p.size(), 1);
  expect_active_entries(active_tree_field(p, s, ActiveSet{ones.data(), 1}), testing::tree_field(p, s),
                        ActiveSet{ones.data(), 1}, 0);

  // θ = 0 opens every node: the same terms as the full walk in another order.
  s.opening = 0;
  const double u = std::numeric_limits<Real>::epsilon() / 2;
  for (std::int32_t min_bin : {1, 2, 3}) {
    SCOPED_TRACE(min_bin);
    const ActiveSet set{bins.data(), min_bin};
    // Round-off of a sum of N terms of mixed sign: ~u·√N·Σ|term| (Σ|term|
    // about 30 |a| for a Plummer sphere's outskirts: generous margin).
    expect_active_entries(active_tree_field(p, s, set), testing::tree_field(p, s), set, u * 64 * std::sqrt(3000.0));
  }

  // θ = 0.5: the active groups' tighter boxes open fewer nodes, so the
  // active-only field is as close to the direct sum as the full one is.
  s.opening = 0.5;
  GravityField<Real> direct;
  direct_sum(p, Real(s.softening), 64, direct);
  const ActiveSet set{bins.data(), 2};
  const GravityField<Real> full = testing::tree_field(p, s), active = active_tree_field(p, s, set);
  std::vector<double> e_full, e_active;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!set.contains(i)) continue;
    auto err = [&](const GravityField<Real>& f) {
      double d2 = 0, r2 = 0;
      for (int a = 0; a < 3; ++a) {
        d2 += std::pow(double(f.acceleration[a][i]) - double(direct.acceleration[a][i]), 2);
        r2 += std::pow(double(direct.acceleration[a][i]), 2);
      }
      return std::sqrt(d2 / r2);
    };
    e_full.push_back(err(full));
    e_active.push_back(err(active));
  }
  std::sort(e_full.begin(), e_full.end());
  std::sort(e_active.begin(), e_active.end());
  for (double q : {0.5, 0.99}) {
    SCOPED_TRACE(q);
    EXPECT_LE(testing::quantile(e_active, q), 1.2 * testing::quantile(e_full, q) + 1e-6);
  }
}

// The solver writes the active particles' acceleration and potential only.
TYPED_TEST(BlockStepsTest, GravityForceAddsOnlyToTheActiveParticles) {
  using Real = TypeParam;
  ParticleSet<Real> p = plummer<Real>(700, 11);
  GravityForce<Real> g{GravitySettings{}};
  g.declare_fields(p);
  const std::vector<std::int32_t> bins = scattered_bins(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) p.acceleration.set(i, Vec3<Real>{1, 2, 3});
  SolverContext<Real> ctx{0, 64, nullptr, nullptr, ActiveSet{bins.data(), 3}, nullptr};
  g.add_acceleration(p, ctx);
  GravityField<Real> full;
  BarnesHut<Real>(GravitySettings{}).compute(p, full, 64);
  std::size_t active = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (bins[i] < 3) {
      ASSERT_EQ(p.acceleration.x[i], Real(1));
      continue;
    }
    ++active;
    // Particle walk of the own-sort tree vs the group walk: the same law, both within the opening error.
    EXPECT_NEAR(double(p.acceleration.y[i]) - 2, double(full.acceleration.y[i]),
                0.05 * std::abs(double(full.acceleration.y[i])) + 1e-3);
  }
  EXPECT_EQ(g.stats().walked, active);
}

// ---- The stepper -------------------------------------------------------------

template <class Real>
Simulation<Real> block_simulation(ParticleSet<Real> p, double dt, const GravitySettings& g, int max_bin,
                                  double eta = 0.5) {
  SimulationSettings s;
  s.dt = dt;
  s.block_size = 128;
  Simulation<Real> sim(std::move(p), s,
                       std::make_unique<integrate::BlockStepper<Real>>(
                           integrate::BlockStepOptions{eta, g.softening, max_bin}));
  sim.add_solver(std::make_unique<GravityForce<Real>>(g, SelfGravityOptions{1, eta}));
  return sim;
}

TYPED_TEST(BlockStepsTest, WithOneBinItIsTheGlobalLeapfrogBitForBit) {
  using Real = TypeParam;
  const ParticleSet<Real> p0 = plummer<Real>(800, 2);
  GravitySettings g;
  SimulationSettings s;
  s.dt = 0.01;
  s.block_size = 128;
  Simulation<Real> leapfrog(p0, s, std::make_unique<integrate::KickDriftStepper<Real>>(integrate::Method::LeapfrogKDK));
  leapfrog.add_solver(std::make_unique<GravityForce<Real>>(g));
  Simulation<Real> block = block_simulation(p0, 0.01, g, 0);
  leapfrog.start();
  block.start();
  for (int k = 0; k < 8; ++k) {
    leapfrog.step();
    block.step();
  }
  EXPECT_TRUE(testing::same_bits(leapfrog.particles(), block.particles()));
}

// A Kepler pair of masses 0.9 and 0.1 on an ellipse of eccentricity 0.9
// (G = M = a = 1, period 2π): the light body's |a| is 9× the heavy one's, so
// the two sit in different bins, and both bins follow the orbit from
// apocentre (coarse) to pericentre (fine). Against the global adaptive step
// at the same η: no larger energy error over 10 periods, no more force
// evaluations, and the orbit closes (the leapfrog's phase error, second order).
struct KeplerRun {
  double worst = 0;        // largest |E/E0 − 1| at the steps
  double drift = 0;        // the light body's distance from its start after 10 periods
  double evaluations = 0;  // particle-force evaluations
  int finest = 0, spread = 0;  // finest bin, largest difference of the two bins
};

KeplerRun kepler(bool block) {
  const double e = 0.9, r_apo = 1 + e, masses[2] = {0.9, 0.1};
  const double v_apo = std::sqrt((1 - e) / (1 + e));  // relative speed at apocentre, GM = a = 1
  ParticleSet<double> p(2);
  for (std::size_t i = 0; i < 2; ++i) {
    // Each body at its share of the separation from the centre of mass, at rest.
    const double share = i == 0 ? -masses[1] : masses[0];
    p.position.set(i, Vec3<double>{share * r_apo, 0, 0});
    p.velocity.set(i, Vec3<double>{0, share * v_apo, 0});
    p.mass[i] = masses[i];
    p.id[i] = i;
  }
  const ParticleSet<double> start = p;
  GravitySettings g;
  g.method = Method::Direct;
  g.softening = 1e-4;  // far below the pericentre distance 0.1: Kepler's law
  constexpr double eta = 0.25, dt = 2 * std::numbers::pi / 64;
  Simulation<double> sim = [&] {
    if (block) return block_simulation(std::move(p), dt, g, 20, eta);
    SimulationSettings s;
    s.dt = dt;  // dt_max
    s.adaptive = true;
    Simulation<double> global(std::move(p), s);
    global.add_solver(std::make_unique<GravityForce<double>>(g, SelfGravityOptions{1, eta}));
    return global;
  }();
  sim.start();
  auto energy = [&] {
    const auto& q = sim.particles();
    double k = 0;
    for (std::size_t i = 0; i < 2; ++i) k += 0.5 * q.mass[i] * dot(q.velocity.get(i), q.velocity.get(i));
    const Vec3<double> d = q.position.get(0) - q.position.get(1);
    return k - q.mass[0] * q.mass[1] / std::sqrt(dot(d, d) + g.softening * g.softening);
  };
  const double e0 = energy();
  KeplerRun out;
  const double period = 2 * std::numbers::pi;
  while (sim.time() < 10 * period * (1 - 1e-12)) {
    sim.step(10 * period);
    out.worst = std::max(out.worst, std::abs(energy() / e0 - 1));
    const auto& q = sim.particles();
    if (block) {
      const auto& bins = q.int_field(q.find_int_field(integrate::kTimeBinField));
      out.finest = std::max({out.finest, int(bins[0]), int(bins[1])});
      out.spread = std::max(out.spread, std::abs(int(bins[0]) - int(bins[1])));
    }
  }
  const auto& q = sim.particles();
  const std::size_t light = q.id[0] == 1 ? 0 : 1;
  out.drift = norm(q.position.get(light) - start.position.get(1));
  NamedValues metrics;
  sim.solvers().front()->add_metrics(metrics);
  out.evaluations = *find_value(metrics, "particle_force_evaluations");
  return out;
}

TEST(BlockSteps, AnEccentricKeplerPairInTwoBinsMatchesTheGlobalStep) {
  const int saved = parallel::thread_count();
  parallel::set_thread_count(1);
  const KeplerRun block = kepler(true), global = kepler(false);
  parallel::set_thread_count(saved);
  EXPECT_GE(block.finest, 5) << "the pericentre should need bins well below the base step";
  EXPECT_GE(block.spread, 1) << "the light body should sit in a finer bin than the heavy one";
  // Measured: block 8.8e-5 with 45 616 evaluations (finest bin 9, bins 2 apart), global 1.3e-4 with 47 688.
  EXPECT_LE(block.worst, 1.2 * global.worst);
  EXPECT_LE(block.evaluations, global.evaluations);
  EXPECT_LT(block.worst, 5e-4);
  EXPECT_LT(block.drift, 2e-3) << "after 10 periods the orbit should close";  // measured 1.0e-4
}

// A Plummer sphere (N = 512, ε = 0.01, direct sum): over one crossing time
// the block steps keep the energy as well as a global step of the finest
// bin's size would, at a fraction of the particle-force evaluations.
TYPED_TEST(BlockStepsTest, APlummerSphereKeepsItsEnergyWithFewerEvaluations) {
  using Real = TypeParam;
  GravitySettings g;
  g.method = Method::Direct;
  g.softening = 0.01;
  const ParticleSet<Real> p0 = plummer<Real>(512, 17);
  Simulation<Real> sim = block_simulation(p0, 1.0 / 16, g, 12, 0.1);
  sim.start();
  auto energy = [&] { return diagnose(sim.particles(), 128).total; };  // K + ½Σmφ
  const double e0 = energy();
  const int steps = 45;  // t = 2.8: one crossing time
  for (int k = 0; k < steps; ++k) sim.step();
  const double error = std::abs(energy() / e0 - 1);
  EXPECT_LT(error, 1e-3);  // measured 3.0e-4 (float and double)
  NamedValues metrics;
  sim.solvers().front()->add_metrics(metrics);
  sim.stepper().add_metrics(metrics);
  const double evaluations = *find_value(metrics, "particle_force_evaluations");
  const double sub_steps = *find_value(metrics, "block_sub_steps");
  // A global step as fine as the finest bin would evaluate every particle at every sub-step.
  EXPECT_GT(sub_steps, double(steps));
  EXPECT_LT(evaluations, 0.5 * sub_steps * double(p0.size()));
}

// Bins, drifts and active-only walks give the same bits on 1, 2 and 3 threads.
TYPED_TEST(BlockStepsTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  const ParticleSet<Real> p0 = plummer<Real>(2000, 23);
  GravitySettings g;
  g.group_size = 64;
  std::vector<ParticleSet<Real>> results;
  const int saved = parallel::thread_count();
  for (int threads : {1, 2, 3}) {
    parallel::set_thread_count(threads);
    Simulation<Real> sim = block_simulation(p0, 1.0 / 32, g, 8, 0.2);
    sim.start();
    for (int k = 0; k < 4; ++k) sim.step();
    results.push_back(sim.particles());
  }
  parallel::set_thread_count(saved);
  EXPECT_TRUE(testing::same_bits(results[0], results[1]));
  EXPECT_TRUE(testing::same_bits(results[0], results[2]));
}

// A run stopped after 3 steps and resumed from its particles, clock and
// state is the run that never stopped, bit for bit.
TYPED_TEST(BlockStepsTest, AResumedRunIsTheRunThatNeverStopped) {
  using Real = TypeParam;
  const ParticleSet<Real> p0 = plummer<Real>(1000, 29);
  GravitySettings g;
  Simulation<Real> whole = block_simulation(p0, 1.0 / 32, g, 8, 0.2);
  whole.start();
  for (int k = 0; k < 6; ++k) whole.step();

  Simulation<Real> first = block_simulation(p0, 1.0 / 32, g, 8, 0.2);
  first.start();
  for (int k = 0; k < 3; ++k) first.step();
  NamedValues state;
  first.save_state(state);
  Simulation<Real> second = block_simulation(first.particles(), 1.0 / 32, g, 8, 0.2);
  second.resume(first.clock(), state);
  for (int k = 0; k < 3; ++k) second.step();
  EXPECT_TRUE(testing::same_bits(whole.particles(), second.particles()));
  EXPECT_EQ(whole.time(), second.time());
}

// A particle that needs a finer bin than max_bin stops the run, named.
TEST(BlockSteps, AParticleBeyondTheFinestBinIsABlowUp) {
  ParticleSet<double> p = plummer<double>(64, 31);
  GravitySettings g;
  g.method = Method::Direct;
  Simulation<double> sim = block_simulation(std::move(p), 1.0, g, 2);
  sim.start();
  try {
    sim.step();
    FAIL() << "expected a blow-up";
  } catch (const SimulationError& e) {
    EXPECT_EQ(e.cause(), BlowUpCause::TimeStep);
    EXPECT_NE(std::string(e.what()).find("max_bin"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swirl::gravity
