// The prescribed rigid motions (boundary/rigid_motion.hpp): each kind's pose
// against its closed form written out here, velocities against central
// differences of the positions, the ramp's continuity, and the swept bounds
// against the positions of a fine sampling in time.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "swirl/boundary/rigid_motion.hpp"

namespace {

using swirl::Vec3d;
using swirl::boundary::RigidMotion;
using swirl::boundary::swept_bounds;

constexpr double kPi = std::numbers::pi;

double distance(const Vec3d& a, const Vec3d& b) { return norm(a - b); }

// Central difference of the position at t (step dt), against the pose's velocity.
double velocity_error(const RigidMotion& m, const Vec3d& x0, double t, double dt = 1e-6) {
  const Vec3d fd = (m.pose(t + dt).position(x0) - m.pose(t - dt).position(x0)) * (0.5 / dt);
  return distance(fd, m.pose(t).velocity(x0));
}

RigidMotion piston() {
  RigidMotion m;
  m.kind = RigidMotion::Kind::Piston;
  m.direction = {2, 0, 0};  // any length
  m.amplitude = 0.05;
  m.frequency = 1.5;
  m.phase_deg = 30;
  return m;
}

RigidMotion flap() {
  RigidMotion m;
  m.kind = RigidMotion::Kind::Flap;
  m.axis = {0, 3, 0};
  m.point = {0.5, 0.2, 0.0};
  m.amplitude_deg = 10;
  m.frequency = 0.8;
  return m;
}

RigidMotion rotation() {
  RigidMotion m;
  m.kind = RigidMotion::Kind::Rotation;
  m.axis = {0, 0, 1};
  m.point = {0.3, 0.3, 0.0};
  m.angular_velocity = 2.0;
  return m;
}

TEST(RigidMotion, APistonShiftsByTheSineAlongItsDirection) {
  const RigidMotion m = piston();
  const Vec3d x0{0.1, 0.2, 0.3};
  for (double t : {0.0, 0.1, 0.37, 1.2}) {
    const double s = 0.05 * std::sin(2 * kPi * 1.5 * t + kPi / 6);
    const double v = 0.05 * 2 * kPi * 1.5 * std::cos(2 * kPi * 1.5 * t + kPi / 6);
    EXPECT_LT(distance(m.pose(t).position(x0), x0 + Vec3d{s, 0, 0}), 1e-15) << t;
    if (t > 0) {
      EXPECT_LT(distance(m.pose(t).velocity(x0), Vec3d{v, 0, 0}), 1e-14) << t;
    }
  }
}

TEST(RigidMotion, AFlapTurnsAboutItsHingeByTheSine) {
  const RigidMotion m = flap();
  const Vec3d x0{0.5, 0.7, 0.4};  // 0.4 above the hinge line (y axis through (0.5, ·, 0))
  for (double t : {0.1, 0.3, 0.9}) {
    const double theta = 10 * kPi / 180 * std::sin(2 * kPi * 0.8 * t);
    // About +y, a point above the hinge goes towards +x for θ > 0.
    const Vec3d expected{0.5 + 0.4 * std::sin(theta), 0.7, 0.4 * std::cos(theta)};
    EXPECT_LT(distance(m.pose(t).position(x0), expected), 1e-15) << t;
    EXPECT_LT(velocity_error(m, x0, t), 1e-8) << t;
  }
}

TEST(RigidMotion, ARotationTurnsAtItsAngularVelocityAfterTheRamp) {
  RigidMotion m = rotation();
  m.ramp = 0.5;
  m.start = 0.2;
  const Vec3d x0{0.5, 0.3, 0.1};  // radius 0.2 about the shaft
  // Before the start: at rest where it was put.
  EXPECT_EQ(m.pose(0.1).position(x0), x0);
  EXPECT_EQ(m.pose(0.1).velocity(x0), Vec3d{});
  // After the ramp: θ = ω0 (T/2 + τ − T).
  const double t = 1.4, theta = 2.0 * (0.25 + (t - 0.2 - 0.5));
  const Vec3d expected{0.3 + 0.2 * std::cos(theta), 0.3 + 0.2 * std::sin(theta), 0.1};
  EXPECT_LT(distance(m.pose(t).position(x0), expected), 1e-15);
  EXPECT_NEAR(norm(m.pose(t).velocity(x0)), 0.4, 1e-14);  // |ω| r
  for (double s : {0.25, 0.45, 0.69, 0.71, 1.0}) EXPECT_LT(velocity_error(m, x0, s), 1e-8) << s;
}

TEST(RigidMotion, TheRampMakesPositionAndVelocityContinuousAtTheStart) {
  for (RigidMotion m : {piston(), flap(), rotation()}) {
    m.start = 0.3;
    m.ramp = 0.4;
    const Vec3d x0{0.2, 0.4, 0.6};
    const Vec3d before = m.pose(0.3 - 1e-9).position(x0), after = m.pose(0.3 + 1e-9).position(x0);
    EXPECT_LT(distance(before, after), 1e-12);
    EXPECT_LT(norm(m.pose(0.3 + 1e-9).velocity(x0)), 1e-7);
    // Across the ramp's end the velocity is continuous too, and matches the positions' derivative throughout.
    EXPECT_LT(distance(m.pose(0.7 - 1e-9).velocity(x0), m.pose(0.7 + 1e-9).velocity(x0)), 1e-7);
    for (double t : {0.35, 0.5, 0.65, 0.9}) EXPECT_LT(velocity_error(m, x0, t), 1e-8) << t;
  }
  // Without a ramp a piston with φ = 30° starts displaced by A sin φ and jumps to its full speed.
  const RigidMotion m = piston();
  EXPECT_NEAR(m.pose(0).position(Vec3d{}).x, 0.025, 1e-15);
  EXPECT_GT(m.pose(1e-9).velocity(Vec3d{}).x, 0.4);
}

TEST(RigidMotion, TheSweptBoundsHoldEveryPositionAndAreReached) {
  const Vec3d x0{0.5, 0.6, 0.4};
  for (const RigidMotion& m : {piston(), flap(), rotation()}) {
    const auto b = swept_bounds(m, x0);
    Vec3d lo = x0, hi = x0;
    for (int k = 0; k <= 20000; ++k) {
      const Vec3d x = m.pose(5.0 * k / 20000).position(x0);
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(x[a], b[0][a] - 1e-12);
        EXPECT_LE(x[a], b[1][a] + 1e-12);
        lo[a] = std::min(lo[a], x[a]), hi[a] = std::max(hi[a], x[a]);
      }
    }
    for (int a = 0; a < 3; ++a) {  // tight: the sampled path comes within 1e-5 of each bound
      EXPECT_LT(lo[a] - b[0][a], 1e-5) << a;
      EXPECT_LT(b[1][a] - hi[a], 1e-5) << a;
    }
  }
}

}  // namespace
