// Adaptive time steps: the step the controller chooses, landing on requested
// times, second-order accuracy, determinism across thread counts and resume.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "swirl/force/uniform_gravity.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"
#include "test_support.hpp"

namespace {

using swirl::ParticleSet;
using swirl::Simulation;
using swirl::SimulationSettings;
using swirl::Vec3;

template <class Real>
class AdaptiveTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(AdaptiveTest, Precisions);

// Particles in the unit box with random velocities, pulled to the centre by a
// spring and down by gravity; the gravity condition (ε = 0.01) limits the step.
template <class Real>
Simulation<Real> springy(std::size_t n, double eta = 0.5, double dt_max = 0.05) {
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      p.position[axis][i] = Real(0.05 + 0.9 * swirl::testing::hash01(3 * i + axis));
      p.velocity[axis][i] = Real(3.0 * (swirl::testing::hash01(4242 + 3 * i + axis) - 0.5));
    }
    p.mass[i] = Real(1);
    p.id[i] = i;
  }
  SimulationSettings s;
  s.dt = dt_max;
  s.adaptive = true;
  s.block_size = 64;
  s.box = swirl::boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.7};
  Simulation<Real> sim(std::move(p), s);
  sim.add_solver(swirl::testing::gravity_conditions<Real>(0.01, eta));
  sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(Real(6), Real(0.5)));
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-9.81)}));
  return sim;
}

template <class Real>
bool bit_identical(const ParticleSet<Real>& a, const ParticleSet<Real>& b) {
  const auto fa = a.fields(), fb = b.fields();
  if (fa.size() != fb.size()) return false;
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      if (std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(Real)) != 0) return false;
  return a.id == b.id;
}

TYPED_TEST(AdaptiveTest, TheStepIsTheTightestLimitCappedByGrowthAndDtMax) {
  using Real = TypeParam;
  auto sim = springy<Real>(200);
  sim.start();
  double previous = 0;
  for (int s = 0; s < 50; ++s) {
    double expected = std::min(swirl::testing::limit_named(sim, "gravity").dt, 0.05);
    if (previous > 0) expected = std::min(expected, 1.25 * previous);
    ASSERT_EQ(sim.proposed_dt(), expected) << s;
    const double t0 = sim.time();
    sim.step();
    EXPECT_EQ(sim.last_dt(), expected);
    EXPECT_EQ(sim.time(), t0 + expected);
    previous = expected;
  }
  EXPECT_LT(sim.last_dt(), 0.05);  // the condition, not the cap, set the steps
}

TYPED_TEST(AdaptiveTest, WithoutConditionsTheStepIsDtMax) {
  using Real = TypeParam;
  ParticleSet<Real> p(3);
  SimulationSettings s;
  s.dt = 0.125;
  s.adaptive = true;
  Simulation<Real> sim(std::move(p), s);
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-1)}));
  sim.start();
  for (int k = 0; k < 4; ++k) sim.step();
  EXPECT_EQ(sim.time(), 0.5);
  EXPECT_EQ(sim.last_dt(), 0.125);
}

TYPED_TEST(AdaptiveTest, StepsLandExactlyOnRequestedTimes) {
  using Real = TypeParam;
  auto sim = springy<Real>(100);
  sim.start();
  const double interval = 0.07;  // not a multiple of any step
  for (int k = 1; k <= 6; ++k) {
    const double target = k * interval;
    int steps = 0;
    while (sim.time() < target) {
      const double before = sim.time();
      sim.step(target);
      ASSERT_LE(sim.last_dt(), sim.clock().previous_dt * (1 + 1e-9));  // never longer than the choice (but for rounding)
      ASSERT_GT(sim.time(), before);
      ASSERT_LT(++steps, 10000);
    }
    EXPECT_EQ(sim.time(), target) << k;  // exactly, not within rounding
  }
}

// Velocity Verlet with steps η·sqrt(ε/|a|) stays second order: on an
// eccentric orbit of a harmonic oscillator (|a| varies along it), halving η
// quarters the error after one period.
TYPED_TEST(AdaptiveTest, VariableStepVerletIsSecondOrder) {
  using Real = double;  // the float round-off would hide the error of the finer run
  (void)sizeof(TypeParam);
  auto error_with = [](double eta) {
    ParticleSet<Real> p(1);
    p.mass[0] = 1;
    p.position.x[0] = 1;
    p.velocity.y[0] = 0.3;  // x = cos t, y = 0.3 sin t for ω = 1
    SimulationSettings s;
    s.dt = eta;  // the cap scales with η too
    s.adaptive = true;
    Simulation<Real> sim(std::move(p), s);
    sim.add_solver(swirl::testing::gravity_conditions<Real>(0.05, eta));
    sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(1.0, 0.0));
    sim.start();
    const double period = 2 * M_PI;
    while (sim.time() < period) sim.step(period);
    const auto& q = sim.particles();
    return std::hypot(q.position.x[0] - 1.0, q.position.y[0]) + std::hypot(q.velocity.x[0], q.velocity.y[0] - 0.3);
  };
  const double coarse = error_with(0.2), fine = error_with(0.1);
  EXPECT_GT(coarse, 1e-4);
  EXPECT_NEAR(coarse / fine, 4.0, 0.8);
}

TYPED_TEST(AdaptiveTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  auto run = [](int threads) {
    swirl::parallel::set_thread_count(threads);
    auto sim = springy<Real>(2000);
    sim.start();
    for (int s = 0; s < 60; ++s) sim.step(0.3);
    return std::make_pair(sim.particles(), sim.time());
  };
  const auto one = run(1), two = run(2), three = run(3);
  EXPECT_TRUE(bit_identical(one.first, two.first));
  EXPECT_TRUE(bit_identical(one.first, three.first));
  EXPECT_EQ(one.second, two.second);
  EXPECT_EQ(one.second, three.second);
}

// What a checkpoint keeps (every field, the step, the time and the
// controller's state) is enough to continue bit-identically.
TYPED_TEST(AdaptiveTest, ResumingMidRunIsBitIdentical) {
  using Real = TypeParam;
  auto straight = springy<Real>(500);
  straight.start();
  for (int s = 0; s < 70; ++s) straight.step(0.5);

  auto first = springy<Real>(500);
  first.start();
  for (int s = 0; s < 30; ++s) first.step(0.5);
  auto second = springy<Real>(500);
  second.particles() = first.particles();
  swirl::NamedValues state;
  first.save_state(state);
  second.resume(first.clock(), state);
  for (int s = 0; s < 40; ++s) second.step(0.5);

  EXPECT_TRUE(bit_identical(straight.particles(), second.particles()));
  EXPECT_EQ(straight.time(), second.time());
  EXPECT_EQ(straight.proposed_dt(), second.proposed_dt());
}

// A force that keeps growing drives the step below its floor: reported as a
// collapse before the step is taken, naming the particle that sets it.
TYPED_TEST(AdaptiveTest, ACollapsingStepIsABlowUp) {
  using Real = TypeParam;
  class Runaway final : public swirl::Solver<Real> {
   public:
    std::string_view name() const override { return "runaway"; }
    void add_acceleration(ParticleSet<Real>& p, const swirl::SolverContext<Real>&) override {
      scale_ *= 100;
      p.acceleration.x[1] += Real(scale_);
    }
    double scale_ = 1;
  };
  ParticleSet<Real> p(3);
  for (std::size_t i = 0; i < 3; ++i) p.id[i] = 7 + i;
  SimulationSettings s;
  s.dt = 0.1;
  s.adaptive = true;
  Simulation<Real> sim(std::move(p), s);
  sim.add_solver(swirl::testing::gravity_conditions<Real>(0.01, 0.5));
  sim.add_solver(std::make_unique<Runaway>());
  sim.start();
  try {
    for (int k = 0; k < 20; ++k) sim.step();
    FAIL() << "no collapse";
  } catch (const swirl::SimulationError& e) {
    EXPECT_EQ(e.cause(), swirl::BlowUpCause::StepCollapse);
    const std::string m = e.what();
    EXPECT_NE(m.find("collapsed"), std::string::npos) << m;
    EXPECT_NE(m.find("particle id 8"), std::string::npos) << m;
  }
}

}  // namespace
