// The thesis's time step: velocity Verlet and the two box passes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "swirl/force/uniform_gravity.hpp"
#include "swirl/sim/simulation.hpp"
#include "test_support.hpp"

namespace {

using swirl::ParticleSet;
using swirl::Simulation;
using swirl::SimulationSettings;
using swirl::Vec3;

template <class Real>
class StepTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(StepTest, Precisions);

template <class Real>
Real eps() { return std::numeric_limits<Real>::epsilon(); }

TYPED_TEST(StepTest, BallisticParticlesFollowTheExactParabola) {
  using Real = TypeParam;
  constexpr std::size_t n = 50;
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = double(i);
    p.position.set(i, Vec3<double>{0.1 * s, -0.2 * s, 1.0 + 0.05 * s}.cast<Real>());
    p.velocity.set(i, Vec3<double>{1.0 - 0.03 * s, 0.5, 2.0 + 0.1 * s}.cast<Real>());
    p.mass[i] = Real(1);
    p.id[i] = i;
  }
  const ParticleSet<Real> initial = p;
  const Vec3<double> g{0.3, -1.5, -9.81};
  SimulationSettings settings;
  settings.dt = 1.0 / 64;  // a power of two keeps t = n·dt exact
  settings.block_size = 8;
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(g.cast<Real>()));
  sim.start();
  constexpr int steps = 200;
  for (int s = 0; s < steps; ++s) sim.step();

  const double t = sim.time();
  ASSERT_EQ(t, steps / 64.0);
  // Round-off: at most ~one ulp of |x| (≤ 50 here) per step, accumulated over the steps.
  const double tol = 2.0 * steps * double(eps<Real>()) * 50.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      const double x0 = initial.position[axis][i], v0 = initial.velocity[axis][i];
      EXPECT_NEAR(sim.particles().position[axis][i], x0 + v0 * t + 0.5 * g[axis] * t * t, tol);
      EXPECT_NEAR(sim.particles().velocity[axis][i], v0 + g[axis] * t, tol / 10);
      EXPECT_EQ(sim.particles().acceleration[axis][i], Real(g[axis]));
    }
  }
}

TYPED_TEST(StepTest, FirstStepDoesNotKickTheInitialVelocityTwice) {
  using Real = TypeParam;
  ParticleSet<Real> p(1);
  p.mass[0] = Real(1);
  SimulationSettings settings;
  settings.dt = 0.5;
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-2)}));
  sim.start();
  EXPECT_EQ(sim.particles().acceleration_prev.z[0], Real(-2));  // a_prev = a₀
  sim.step();
  EXPECT_EQ(sim.particles().position.z[0], Real(-0.25));  // ½·g·dt²
  EXPECT_EQ(sim.particles().velocity.z[0], Real(-1));     // g·dt
}

TYPED_TEST(StepTest, VelocityVerletIsSecondOrderOnAHarmonicOscillator) {
  using Real = TypeParam;
  // Error at t = 2π/ω should fall ~4x when dt halves.
  auto error_with = [](int steps_per_period) {
    ParticleSet<Real> p(1);
    p.mass[0] = Real(1);
    p.position.x[0] = Real(1);
    SimulationSettings settings;
    settings.dt = 2 * M_PI / steps_per_period;
    Simulation<Real> sim(std::move(p), settings);
    sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(Real(1), Real(0)));
    sim.start();
    for (int s = 0; s < steps_per_period; ++s) sim.step();
    return std::abs(double(sim.particles().position.x[0]) - 1.0) + std::abs(double(sim.particles().velocity.x[0]));
  };
  const double coarse = error_with(50), fine = error_with(100);
  EXPECT_GT(coarse, 1e-4);  // not accidentally exact
  EXPECT_NEAR(coarse / fine, 4.0, 0.4);
}

// One particle thrown at a wall, no gravity.
template <class Real>
Simulation<Real> thrown_at_wall(double vx, double restitution) {
  ParticleSet<Real> p(1);
  p.mass[0] = Real(1);
  p.position.set(0, Vec3<Real>{Real(0.9), Real(0.5), Real(0.5)});
  p.velocity.set(0, Vec3<double>{vx, 0.3, -0.2}.cast<Real>());
  SimulationSettings settings;
  settings.dt = 0.013;
  settings.box = swirl::boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, restitution};
  return Simulation<Real>(std::move(p), settings);
}

TYPED_TEST(StepTest, AWallReflectsTheNormalVelocityScaledByRestitution) {
  using Real = TypeParam;
  for (double e : {0.0, 0.5, 1.0}) {
    auto sim = thrown_at_wall<Real>(2.0, e);
    sim.start();
    int steps = 0;
    while (sim.particles().velocity.x[0] > 0 && steps < 1000) {
      sim.step();
      ++steps;
    }
    ASSERT_LT(steps, 1000);
    EXPECT_EQ(sim.particles().velocity.x[0], Real(-e * Real(2.0))) << "e = " << e;
    // Only the normal component changes.
    EXPECT_EQ(sim.particles().velocity.y[0], Real(0.3));
    EXPECT_EQ(sim.particles().velocity.z[0], Real(-0.2));
  }
}

TYPED_TEST(StepTest, NoParticleEndsAStepFurtherOutsideThanItsStep) {
  using Real = TypeParam;
  constexpr std::size_t n = 400;
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      p.position[axis][i] = Real(0.05 + 0.9 * swirl::testing::hash01(3 * i + axis));
      p.velocity[axis][i] = Real(8.0 * (swirl::testing::hash01(1000 + 3 * i + axis) - 0.5));
    }
    p.mass[i] = Real(1);
    p.id[i] = i;
  }
  SimulationSettings settings;
  settings.dt = 0.01;
  settings.block_size = 16;
  const Vec3<double> g{0, 0, -9.81};
  settings.box = swirl::boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.3};
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(g.template cast<Real>()));
  sim.start();
  std::size_t ever_outside = 0;
  for (int s = 0; s < 300; ++s) {
    const ParticleSet<Real> before = sim.particles();
    sim.step();
    const auto& q = sim.particles();
    for (std::size_t i = 0; i < n; ++i) {
      double speed2 = 0, outside = 0;
      for (int axis = 0; axis < 3; ++axis) {
        speed2 += double(before.velocity[axis][i]) * double(before.velocity[axis][i]);
        const double x = q.position[axis][i];
        outside = std::max({outside, 0.0 - x, x - 1.0});
      }
      if (outside > 0) ++ever_outside;
      // |v|·Δt plus the ½|g|·Δt² of this step's acceleration, plus round-off.
      const double bound = std::sqrt(speed2) * settings.dt + 0.5 * 9.81 * settings.dt * settings.dt + 1e-5;
      ASSERT_LE(outside, bound) << "particle " << i << " step " << s;
    }
  }
  EXPECT_GT(ever_outside, 0u);  // the walls were actually hit
}

TYPED_TEST(StepTest, ElasticBouncesConserveKineticEnergy) {
  using Real = TypeParam;
  constexpr std::size_t n = 200;
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      p.position[axis][i] = Real(0.1 + 0.8 * swirl::testing::hash01(7 * i + axis));
      p.velocity[axis][i] = Real(6.0 * (swirl::testing::hash01(5000 + 3 * i + axis) - 0.5));
    }
    p.mass[i] = Real(0.5 + swirl::testing::hash01(9000 + i));
  }
  auto kinetic = [](const ParticleSet<Real>& q) {
    double k = 0;
    for (std::size_t i = 0; i < q.size(); ++i)
      for (int axis = 0; axis < 3; ++axis) k += 0.5 * double(q.mass[i]) * double(q.velocity[axis][i]) * double(q.velocity[axis][i]);
    return k;
  };
  const double k0 = kinetic(p);
  SimulationSettings settings;
  settings.dt = 0.005;
  settings.box = swirl::boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 1.0};
  Simulation<Real> sim(std::move(p), settings);
  sim.start();
  for (int s = 0; s < 2000; ++s) sim.step();  // every particle crosses the box several times
  // With e = 1 a bounce only flips a sign: energy is exact up to nothing at all.
  EXPECT_EQ(kinetic(sim.particles()), k0);
  for (std::size_t i = 0; i < n; ++i)
    for (int axis = 0; axis < 3; ++axis) ASSERT_LE(std::abs(sim.particles().position[axis][i] - Real(0.5)), Real(0.5 + 0.02));
}

TYPED_TEST(StepTest, ABlowUpStopsWithAMessageNamingTheParticle) {
  using Real = TypeParam;
  ParticleSet<Real> p(3);
  for (std::size_t i = 0; i < 3; ++i) { p.mass[i] = Real(1); p.id[i] = 40 + i; }
  p.velocity.x[1] = std::numeric_limits<Real>::infinity();
  SimulationSettings settings;
  settings.dt = 0.1;
  Simulation<Real> sim(std::move(p), settings);
  try {
    sim.start();  // the initial state is already broken: start() refuses it
    FAIL() << "no error";
  } catch (const swirl::SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("particle id 41 has a non-finite velocity"), std::string::npos) << e.what();
  }
}

TEST(Simulation, RefusesBadSettings) {
  SimulationSettings settings;
  settings.dt = 0;
  EXPECT_THROW(Simulation<double>(ParticleSet<double>(1), settings), std::invalid_argument);
  settings.dt = -1;
  EXPECT_THROW(Simulation<double>(ParticleSet<double>(1), settings), std::invalid_argument);
  settings.dt = 1;
  settings.block_size = 0;
  EXPECT_THROW(Simulation<double>(ParticleSet<double>(1), settings), std::invalid_argument);
  settings.block_size = 1;
  Simulation<double> sim(ParticleSet<double>(1), settings);
  EXPECT_THROW(sim.step(), std::logic_error);
}

}  // namespace
