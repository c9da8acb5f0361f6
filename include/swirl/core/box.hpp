// An axis-aligned box [lo, hi] in metres (SPH) or length units (gravity).
#pragma once

#include "swirl/core/vec3.hpp"

namespace swirl {

template <class Real>
struct Box {
  Vec3<Real> lo{};
  Vec3<Real> hi{};

  // True when p lies inside or on the faces of the box.
  constexpr bool contains(const Vec3<Real>& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  constexpr Vec3<Real> extent() const { return hi - lo; }
  constexpr Real volume() const { const auto e = extent(); return e.x * e.y * e.z; }
  // A box is valid when every extent is positive.
  constexpr bool valid() const { return hi.x > lo.x && hi.y > lo.y && hi.z > lo.z; }

  template <class Other>
  constexpr Box<Other> cast() const { return {lo.template cast<Other>(), hi.template cast<Other>()}; }
};

}  // namespace swirl
