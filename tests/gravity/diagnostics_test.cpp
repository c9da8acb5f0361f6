// Energies, momenta and the virial ratio from the walk's potential.
#include <gtest/gtest.h>

#include <cmath>

#include "gravity/gravity_test_util.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class DiagnosticsTest : public ::testing::Test {};
TYPED_TEST_SUITE(DiagnosticsTest, testing::Precisions);

TYPED_TEST(DiagnosticsTest, TwoBodiesByHand) {
  using Real = TypeParam;
  ParticleSet<Real> p(2);
  p.mass[0] = 1;
  p.mass[1] = 3;
  p.position.set(1, {Real(2), 0, 0});
  p.velocity.set(0, {0, Real(1), 0});
  p.velocity.set(1, {0, 0, Real(-1)});
  for (Method method : {Method::Direct, Method::BarnesHut}) {
    GravitySettings s;
    s.method = method;
    s.softening = 0;
    GravityForce<Real> gravity(s);
    swirl::evaluate_alone(gravity, p, 1);
    const Diagnostics d = diagnose(p);
    EXPECT_EQ(d.mass, 4);
    EXPECT_EQ(d.kinetic, 2);           // ½·1·1 + ½·3·1
    EXPECT_EQ(d.potential, -1.5);      // −m₁m₂/r
    EXPECT_EQ(d.total, 0.5);
    EXPECT_EQ(d.virial_ratio, 4 / 1.5);
    EXPECT_EQ(d.momentum, (Vec3d{0, 1, -3}));
    EXPECT_EQ(d.angular_momentum, (Vec3d{0, 6, 0}));  // 3·(2, 0, 0) × (0, 0, −1)
    EXPECT_EQ(d.centre_of_mass, (Vec3d{1.5, 0, 0}));
    EXPECT_EQ(potential_energy(p), -1.5);
    // The force went into the accelerations: a₀ = m₁/r² x̂ = 0.75 x̂.
    EXPECT_EQ(p.acceleration.x[0], Real(0.75));
    p.acceleration.x[0] = 0;
    p.acceleration.x[1] = 0;
  }
}

TYPED_TEST(DiagnosticsTest, MissingPotentialIsAClearError) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(10, 1);
  try {
    diagnose(p);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("potential"), std::string::npos);
  }
  EXPECT_THROW(potential_energy(p), std::invalid_argument);
}

TYPED_TEST(DiagnosticsTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  ParticleSet<Real> p = plummer<Real>(5000, 2);
  GravityForce<Real> gravity;
  swirl::evaluate_alone(gravity, p, 256);
  const int saved = parallel::thread_count();
  parallel::set_thread_count(1);
  const Diagnostics one = diagnose(p, 64);
  for (int threads : {2, 3}) {
    parallel::set_thread_count(threads);
    const Diagnostics d = diagnose(p, 64);
    EXPECT_EQ(d.kinetic, one.kinetic);
    EXPECT_EQ(d.potential, one.potential);
    EXPECT_EQ(d.angular_momentum, one.angular_momentum);
  }
  parallel::set_thread_count(saved);
  EXPECT_NEAR(one.virial_ratio, 1.0, 0.06);
}

}  // namespace
}  // namespace swirl::gravity
