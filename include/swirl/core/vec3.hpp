// A small 3-vector value type for set-up code, configuration and diagnostics.
//
// Hot loops do not use it: they read the component arrays of a ParticleSet
// directly so the compiler can vectorise them.
#pragma once

#include <array>
#include <cmath>
#include <utility>

namespace swirl {

template <class Real>
struct Vec3 {
  Real x{}, y{}, z{};

  constexpr Real& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr Real operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }

  constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3& operator*=(Real s) { x *= s; y *= s; z *= s; return *this; }
  friend constexpr Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
  friend constexpr Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
  friend constexpr Vec3 operator*(Vec3 a, Real s) { return a *= s; }
  friend constexpr Vec3 operator*(Real s, Vec3 a) { return a *= s; }
  friend constexpr bool operator==(const Vec3&, const Vec3&) = default;

  template <class Other>
  constexpr Vec3<Other> cast() const { return {Other(x), Other(y), Other(z)}; }
};

template <class Real>
constexpr Real dot(const Vec3<Real>& a, const Vec3<Real>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

template <class Real>
constexpr Vec3<Real> cross(const Vec3<Real>& a, const Vec3<Real>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <class Real>
Real norm(const Vec3<Real>& a) { return std::sqrt(dot(a, a)); }

// Two unit vectors u, v with (e, u, v) orthonormal and right-handed, for a unit
// vector e: u = e × (the coordinate axis least aligned with e), normalised;
// v = e × u. A pure function of e, so a disc or ring sampled on it is the same
// points every time.
template <class Real>
std::pair<Vec3<Real>, Vec3<Real>> basis_around(const Vec3<Real>& e) {
  Vec3<Real> other{1, 0, 0};
  if (std::abs(e.y) <= std::abs(e.x) && std::abs(e.y) <= std::abs(e.z)) other = {0, 1, 0};
  else if (std::abs(e.z) <= std::abs(e.x) && std::abs(e.z) <= std::abs(e.y)) other = {0, 0, 1};
  Vec3<Real> u = cross(e, other);
  u = u * (Real(1) / norm(u));
  return {u, cross(e, u)};
}

using Vec3d = Vec3<double>;

}  // namespace swirl
