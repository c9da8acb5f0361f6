// RigidMotion: a prescribed rigid motion of an obstacle (a piston wave-maker,
// a flap paddle, a rotating paddle), given in closed form, so that the pose at
// any time t is a function of t alone: a run resumed from a checkpoint puts
// the obstacle exactly where the uninterrupted run has it, with no state.
//
// A point whose rest position is x0 (the obstacle as the scene places it) is
// at
//   x(t) = c + R(t)·(x0 − c) + s(t),   v(t) = ω(t) × R(t)·(x0 − c) + ṡ(t)
// with c the pivot (`point`), R(t) the rotation by θ(t) about the unit axis â,
// ω = θ'(t)·â, and s(t) a shift along the unit direction d̂. With τ = t − start
// and the ramp r(τ) (below):
//   piston    s(τ) = d̂·A·r(τ)·sin(2πfτ + φ),  θ = 0            (A in m)
//   flap      θ(τ) = θ_A·r(τ)·sin(2πfτ + φ),  s = 0            (θ_A in rad)
//   rotation  θ(τ) = ω0·∫₀^τ r,                s = 0            (ω0 in rad/s)
// Before `start` (τ < 0) the pose is the one at τ = 0 and the velocity 0.
// The ramp eases the motion in: r(τ) = (1 − cos(πτ/T))/2 for 0 ≤ τ < T and 1
// after (T = `ramp`; T = 0: r = 1 throughout). With T > 0 the position and
// the velocity are continuous at `start`; with T = 0 the velocity jumps there
// (an impulsive start), and a piston or flap with φ ≠ 0 starts displaced.
//
// Invariants (checked by the scene's validation): direction and axis not zero
// (normalised here), frequency > 0 for piston and flap, every number finite.
// Units: SI (m, s, rad).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string_view>

#include "swirl/core/enum_names.hpp"
#include "swirl/core/vec3.hpp"

namespace swirl::boundary {

struct RigidMotion {
  enum class Kind { Piston, Flap, Rotation };
  Kind kind = Kind::Piston;
  Vec3d direction{1, 0, 0};     // piston: the stroke's direction (any length > 0)
  double amplitude = 0;         // piston: A, m (the stroke is 2A)
  double amplitude_deg = 0;     // flap: θ_A, degrees
  double frequency = 0;         // piston, flap: f, Hz
  double phase_deg = 0;         // piston, flap: φ, degrees
  Vec3d axis{0, 1, 0};          // flap, rotation: the hinge's or the shaft's direction (any length > 0)
  Vec3d point{};                // flap, rotation: a point on that axis, m
  double angular_velocity = 0;  // rotation: ω0, rad/s (right-handed about axis)
  double start = 0;             // s: the motion starts here
  double ramp = 0;              // s: T, the ramp's length (0: none)

  // The pose at one time: x = c + R·(x0 − c) + s, v = ω × R·(x0 − c) + ṡ.
  struct Pose {
    std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // R, row-major
    Vec3d pivot{};                                             // c
    Vec3d shift{};                                             // s
    Vec3d angular_velocity{};                                  // ω
    Vec3d shift_velocity{};                                    // ṡ

    Vec3d rotated(const Vec3d& x0) const {  // R·(x0 − c)
      const Vec3d r = x0 - pivot;
      const auto& m = rotation;
      return {m[0] * r.x + m[1] * r.y + m[2] * r.z, m[3] * r.x + m[4] * r.y + m[5] * r.z,
              m[6] * r.x + m[7] * r.y + m[8] * r.z};
    }
    Vec3d position(const Vec3d& x0) const { return pivot + rotated(x0) + shift; }
    Vec3d velocity(const Vec3d& x0) const {
      const Vec3d r = rotated(x0), w = angular_velocity;
      return cross(w, r) + shift_velocity;
    }
  };

  // The ramp r(τ) and its derivative r'(τ); and ∫₀^τ r (rotation's angle).
  double ramp_value(double tau) const {
    if (tau <= 0) return ramp > 0 ? 0.0 : 1.0;
    if (!(ramp > 0) || tau >= ramp) return 1.0;
    return 0.5 * (1 - std::cos(std::numbers::pi * tau / ramp));
  }
  double ramp_rate(double tau) const {
    if (!(ramp > 0) || tau <= 0 || tau >= ramp) return 0.0;
    return 0.5 * std::numbers::pi / ramp * std::sin(std::numbers::pi * tau / ramp);
  }
  double ramp_integral(double tau) const {
    if (tau <= 0) return 0.0;
    if (!(ramp > 0)) return tau;
    if (tau >= ramp) return 0.5 * ramp + (tau - ramp);
    return 0.5 * tau - 0.5 * ramp / std::numbers::pi * std::sin(std::numbers::pi * tau / ramp);
  }

  // The scalar of the motion at τ (piston: the shift along d̂ in m; flap and
  // rotation: θ in rad) and its rate (τ < 0: the value at 0, rate 0).
  std::array<double, 2> amount(double t) const {
    const double tau = std::max(t - start, 0.0);
    const bool moving = t > start;
    if (kind == Kind::Rotation) return {angular_velocity * ramp_integral(tau), moving ? angular_velocity * ramp_value(tau) : 0.0};
    const double a = kind == Kind::Piston ? amplitude : amplitude_deg * std::numbers::pi / 180;
    const double w = 2 * std::numbers::pi * frequency, phi = phase_deg * std::numbers::pi / 180;
    const double arg = w * tau + phi, r = ramp_value(tau);
    const double value = a * r * std::sin(arg);
    const double rate = moving ? a * (ramp_rate(tau) * std::sin(arg) + r * w * std::cos(arg)) : 0.0;
    return {value, rate};
  }

  Pose pose(double t) const {
    Pose p;
    const auto [value, rate] = amount(t);
    if (kind == Kind::Piston) {
      const Vec3d d = direction * (1 / norm(direction));
      p.shift = d * value;
      p.shift_velocity = d * rate;
      return p;
    }
    const Vec3d a = axis * (1 / norm(axis));
    p.pivot = point;
    p.angular_velocity = a * rate;
    // Rodrigues: R = cos θ I + sin θ [a]× + (1 − cos θ) a aᵀ.
    const double c = std::cos(value), s = std::sin(value), k = 1 - c;
    p.rotation = {c + k * a.x * a.x,       k * a.x * a.y - s * a.z, k * a.x * a.z + s * a.y,
                  k * a.y * a.x + s * a.z, c + k * a.y * a.y,       k * a.y * a.z - s * a.x,
                  k * a.z * a.x - s * a.y, k * a.z * a.y + s * a.x, c + k * a.z * a.z};
    return p;
  }

  // The angles θ a flap or a rotation sweeps: [θ_lo, θ_hi] (rad); a rotation
  // sweeps every angle (hi − lo = 2π). Piston: {0, 0}.
  std::array<double, 2> swept_angles() const {
    if (kind == Kind::Rotation) return {0.0, 2 * std::numbers::pi};
    if (kind == Kind::Piston) return {0.0, 0.0};
    const double a = std::abs(amplitude_deg) * std::numbers::pi / 180;
    return {-a, a};
  }
};

inline constexpr std::array<EnumName<RigidMotion::Kind>, 3> kRigidMotionNames{{
    {"piston", RigidMotion::Kind::Piston},
    {"flap", RigidMotion::Kind::Flap},
    {"rotation", RigidMotion::Kind::Rotation},
}};

// The box [lo, hi] that a point with rest position x0 stays inside for every
// t under the motion (exact: the stroke's two ends for a piston; for a flap
// the arc's ends and the arc's extremes along each axis inside it; a
// rotation's whole circle).
inline std::array<Vec3d, 2> swept_bounds(const RigidMotion& m, const Vec3d& x0) {
  if (m.kind == RigidMotion::Kind::Piston) {
    const Vec3d d = m.direction * (std::abs(m.amplitude) / norm(m.direction));
    const Vec3d a = x0 - d, b = x0 + d;
    return {Vec3d{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)},
            Vec3d{std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}};
  }
  // x(θ) = c + (r·â)â + cos θ·u + sin θ·(â × u), u = r − (r·â)â the radial part.
  const Vec3d a = m.axis * (1 / norm(m.axis)), r = x0 - m.point;
  const Vec3d centre = m.point + a * dot(r, a), u = r - a * dot(r, a);
  const Vec3d w = cross(a, u);
  // Plain variables, not a structured binding: clang (the TSan and fuzz
  // builds) refuses to capture a binding in the lambdas below before C++20's P1091.
  const auto swept = m.swept_angles();
  const double lo_angle = swept[0], hi_angle = swept[1];
  Vec3d lo, hi;
  for (int k = 0; k < 3; ++k) {
    // Along axis k: centre_k + R cos(θ − θ*), R = |(u_k, w_k)|, θ* = atan2(w_k, u_k).
    const auto at = [&](double theta) { return centre[k] + std::cos(theta) * u[k] + std::sin(theta) * w[k]; };
    double low = std::min(at(lo_angle), at(hi_angle)), high = std::max(at(lo_angle), at(hi_angle));
    const double radius = std::hypot(u[k], w[k]), peak = std::atan2(w[k], u[k]);
    const auto inside = [&](double theta) {  // θ + 2πn in [lo_angle, hi_angle] for some n
      const double turns = std::ceil((lo_angle - theta) / (2 * std::numbers::pi));
      return theta + turns * 2 * std::numbers::pi <= hi_angle;
    };
    if (inside(peak)) high = std::max(high, centre[k] + radius);
    if (inside(peak + std::numbers::pi)) low = std::min(low, centre[k] - radius);
    lo[k] = low, hi[k] = high;
  }
  return {lo, hi};
}

}  // namespace swirl::boundary
