// The blow-up guard: each class of blow-up triggered on purpose and reported
// with its cause, and legitimate runs left alone.
#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <limits>
#include <memory>
#include <string>

#include "swirl/force/uniform_gravity.hpp"
#include "swirl/sim/simulation.hpp"
#include "test_support.hpp"

namespace {

using swirl::BlowUpCause;
using swirl::OnBlowUp;
using swirl::ParticleSet;
using swirl::Simulation;
using swirl::SimulationError;
using swirl::SimulationSettings;
using swirl::Vec3;

template <class Real>
class GuardTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(GuardTest, Precisions);

// Writes a NaN into one particle's density when the forces are evaluated at
// time `when` or later (a solver going wrong).
template <class Real>
class Poison final : public swirl::Solver<Real> {
 public:
  Poison(std::size_t index, double when) : index_(index), when_(when) {}
  std::string_view name() const override { return "poison"; }
  void add_acceleration(ParticleSet<Real>& p, const swirl::SolverContext<Real>& ctx) override {
    if (ctx.time >= when_) p.density[index_] = std::numeric_limits<Real>::quiet_NaN();
  }

 private:
  std::size_t index_;
  double when_;
};

// n particles in the unit box on a jittered lattice, at rest, ids 100 + i.
template <class Real>
ParticleSet<Real> particles(std::size_t n) {
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) p.position[axis][i] = Real(0.1 + 0.8 * swirl::testing::hash01(3 * i + axis));
    p.mass[i] = Real(1);
    p.density[i] = Real(1000);
    p.id[i] = 100 + i;
  }
  return p;
}

SimulationSettings boxed(double dt) {
  SimulationSettings s;
  s.dt = dt;
  s.block_size = 8;
  s.box = swirl::boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.5};
  return s;
}

// Runs `steps` steps and returns the error they threw (none: cause empty).
template <class Real>
std::pair<std::string, BlowUpCause> error_of(Simulation<Real>& sim, int steps) {
  try {
    for (int s = 0; s < steps; ++s) sim.step();
  } catch (const SimulationError& e) {
    return {e.what(), e.cause()};
  }
  return {"", BlowUpCause::NonFinite};
}

void expect_mentions(const std::string& message, std::initializer_list<std::string> parts) {
  for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

TYPED_TEST(GuardTest, ANaNInjectedIntoAFieldStopsTheRunNamingTheQuantity) {
  using Real = TypeParam;
  Simulation<Real> sim(particles<Real>(50), boxed(0.01));
  sim.add_solver(std::make_unique<Poison<Real>>(17, 0.035));  // the 4th step's forces
  sim.start();
  const auto [message, cause] = error_of(sim, 10);
  ASSERT_FALSE(message.empty());
  EXPECT_EQ(cause, BlowUpCause::NonFinite);
  expect_mentions(message, {"step 4 ", "t = 0.04", "particle id 117", "non-finite density", "fix: a smaller dt"});
  EXPECT_EQ(sim.step_count(), 4u);
}

TYPED_TEST(GuardTest, ANaNStopsTheRunEvenWhenWarningOnly) {
  using Real = TypeParam;
  auto settings = boxed(0.01);
  settings.on_blow_up = OnBlowUp::Warn;
  Simulation<Real> sim(particles<Real>(20), settings);
  sim.add_solver(std::make_unique<Poison<Real>>(3, 0.005));  // from the first step's forces on
  sim.start();
  EXPECT_EQ(error_of(sim, 3).second, BlowUpCause::NonFinite);
}

// Forces of the initial state that are not finite stop start() itself: no
// step exists to blame, and the message says so.
TYPED_TEST(GuardTest, ANaNInTheInitialForcesStopsStartWithoutBlamingTheStep) {
  using Real = TypeParam;
  Simulation<Real> sim(particles<Real>(20), boxed(0.01));
  sim.add_solver(std::make_unique<Poison<Real>>(3, 0.0));
  try {
    sim.start();
    FAIL() << "no error";
  } catch (const swirl::SimulationError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.cause(), BlowUpCause::NonFinite);
    EXPECT_NE(what.find("before the first step: blow-up: the forces of the initial state are not finite: particle id 103 "
                        "has a non-finite density"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("no time step is involved"), std::string::npos) << what;
  }
}

// A spring pulls every particle to the centre; with SPH limits the fastest
// particle sets the CFL condition.
TYPED_TEST(GuardTest, ATooLargeStepViolatesTheCflConditionNamingTheFastestParticle) {
  using Real = TypeParam;
  auto p = particles<Real>(64);
  p.velocity.x[40] = Real(3);  // the fastest: id 140
  auto settings = boxed(0.004);
  // 0.6·0.02/(10 + 3) = 9.2e-4 < 0.004
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(swirl::testing::sph_conditions<Real>(0.02, 10.0, 0.0));
  sim.start();
  const auto [message, cause] = error_of(sim, 5);
  ASSERT_FALSE(message.empty());
  EXPECT_EQ(cause, BlowUpCause::TimeStep);
  expect_mentions(message, {"step 1 ", "time step too large", "CFL", "particle id 140", "fix: dt <= 0.000923",
                            "dt = \"adaptive\""});
}

TYPED_TEST(GuardTest, TheForceViscousAndGravityConditionsAreNamedToo) {
  using Real = TypeParam;
  {  // force: a strong spring (|a| up to 1100, so 0.4·sqrt(0.02/1100) = 1.7e-3), a step too short for the CFL to bind
    auto settings = boxed(0.003);
    Simulation<Real> sim(particles<Real>(30), settings);
    sim.add_solver(swirl::testing::sph_conditions<Real>(0.02, 0.1, 0.0));
    sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(Real(40), Real(0.5)));
    sim.start();
    const auto [message, cause] = error_of(sim, 1);
    EXPECT_EQ(cause, BlowUpCause::TimeStep);
    expect_mentions(message, {"force condition", "|a|max"});
  }
  {  // viscous: 0.125·0.02²·1000/μ with μ = 100 is 5e-4
    auto settings = boxed(0.001);
    Simulation<Real> sim(particles<Real>(30), settings);
    sim.add_solver(swirl::testing::sph_conditions<Real>(0.02, 0.1, 100.0));
    sim.start();
    const auto [message, cause] = error_of(sim, 1);
    EXPECT_EQ(cause, BlowUpCause::TimeStep);
    expect_mentions(message, {"viscous condition", "smaller viscosity"});
  }
  {  // gravity, softened
    auto settings = boxed(0.05);
    settings.box.reset();
    Simulation<Real> sim(particles<Real>(30), settings);
    sim.add_solver(swirl::testing::gravity_conditions<Real>(0.01, 0.5));
    sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(Real(10), Real(0.5)));
    sim.start();
    const auto [message, cause] = error_of(sim, 1);
    EXPECT_EQ(cause, BlowUpCause::TimeStep);
    expect_mentions(message, {"gravity condition", "ε", "larger softening"});
  }
}

TYPED_TEST(GuardTest, AParticleShotOutOfTheBoxIsReportedAsLeavingIt) {
  using Real = TypeParam;
  auto p = particles<Real>(40);
  p.position.set(9, Vec3<Real>{Real(0.95), Real(0.5), Real(0.5)});
  p.velocity.x[9] = Real(100);  // 1 m per step of 0.01: far through the wall
  auto settings = boxed(0.01);
  settings.escape_length = 0.05;
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(swirl::testing::sph_conditions<Real>(0.05, 10.0, 0.0));
  sim.start();
  const auto [message, cause] = error_of(sim, 3);
  ASSERT_FALSE(message.empty());
  EXPECT_EQ(cause, BlowUpCause::LeftDomain);  // reported before the CFL condition it also breaks
  expect_mentions(message, {"step 1 ", "particle id 109 left the box", "kernel support h = 0.05", "fix:"});
}

// Particles bouncing in the box at speeds a CFL-respecting step allows never
// trip the escape check, although they end steps outside the walls.
TYPED_TEST(GuardTest, OrdinaryWallContactsAreNotEscapes) {
  using Real = TypeParam;
  constexpr std::size_t n = 300;
  auto p = particles<Real>(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int axis = 0; axis < 3; ++axis) p.velocity[axis][i] = Real(6.0 * (swirl::testing::hash01(999 + 3 * i + axis) - 0.5));
  auto settings = boxed(0.005);
  settings.escape_length = 0.05;  // |v|·dt ≤ 0.026 + ½g·dt²
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-9.81)}));
  sim.start();
  EXPECT_EQ(error_of(sim, 400).first, "");
}

TYPED_TEST(GuardTest, WarnKeepsRunningAndReportsEachFailedCheck) {
  using Real = TypeParam;
  auto p = particles<Real>(64);
  p.velocity.x[40] = Real(3);
  auto settings = boxed(0.004);
  settings.on_blow_up = OnBlowUp::Warn;
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(swirl::testing::sph_conditions<Real>(0.02, 10.0, 0.0));
  sim.start();
  for (int s = 0; s < 5; ++s) {
    sim.step();
    const auto events = sim.take_events();
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].cause, BlowUpCause::TimeStep);
  }
  EXPECT_EQ(sim.step_count(), 5u);
}

TYPED_TEST(GuardTest, OffSkipsTheChecksButNotTheNonFinitePositions) {
  using Real = TypeParam;
  auto p = particles<Real>(64);
  p.velocity.x[40] = Real(3);
  auto settings = boxed(0.004);
  settings.on_blow_up = OnBlowUp::Off;
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(swirl::testing::sph_conditions<Real>(0.02, 10.0, 0.0));
  sim.start();
  EXPECT_EQ(error_of(sim, 5).first, "");
  sim.particles().velocity.y[3] = std::numeric_limits<Real>::infinity();
  EXPECT_EQ(error_of(sim, 1).second, BlowUpCause::NonFinite);
}

// The fused scan against plain loops over the particles (its slow twin).
TYPED_TEST(GuardTest, TheLimitsMatchAPlainEvaluationOfTheConditions) {
  using Real = TypeParam;
  constexpr std::size_t n = 500;
  auto p = particles<Real>(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) p.velocity[axis][i] = Real(2.0 * (swirl::testing::hash01(77 + 3 * i + axis) - 0.5));
    p.density[i] = Real(900 + 200 * swirl::testing::hash01(5555 + i));
  }
  auto settings = boxed(1e-4);
  settings.block_size = 13;
  const std::array<double, 6> sph{0.03, 15.0, 0.8, 0.45, 0.3, 0.1};
  Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(swirl::testing::sph_conditions<Real>(sph[0], sph[1], sph[2], sph[3], sph[4], sph[5]));
  sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(Real(7), Real(0.4)));
  sim.start();
  for (int s = 0; s < 3; ++s) sim.step();
  const auto& q = sim.particles();
  double v2 = 0, a2 = 0, rho = std::numeric_limits<double>::infinity();
  std::size_t fastest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double sv = 0, sa = 0;
    for (int axis = 0; axis < 3; ++axis) {
      sv += double(q.velocity[axis][i]) * double(q.velocity[axis][i]);
      sa += double(q.acceleration[axis][i]) * double(q.acceleration[axis][i]);
    }
    if (sv > v2) v2 = sv, fastest = i;
    a2 = std::max(a2, sa);
    rho = std::min(rho, double(q.density[i]));
  }
  // The scan squares in Real: a few ulps of Real apart.
  const double tol = 8 * double(std::numeric_limits<Real>::epsilon());
  const auto [h, c, mu, cfl, force_factor, viscous_factor] = sph;
  const auto l_cfl = swirl::testing::limit_named(sim, "cfl"), l_force = swirl::testing::limit_named(sim, "force"),
             l_viscous = swirl::testing::limit_named(sim, "viscous");
  EXPECT_NEAR(l_cfl.dt, cfl * h / (c + std::sqrt(v2)), tol * l_cfl.dt);
  EXPECT_EQ(l_cfl.particle, fastest);
  EXPECT_NEAR(l_force.dt, force_factor * std::sqrt(h / std::sqrt(a2)), tol * l_force.dt);
  EXPECT_NEAR(l_viscous.dt, viscous_factor * h * h * rho / mu, tol * l_viscous.dt);
}

}  // namespace
