// The thesis's bounding box (section 4.4): the fluid is kept in an
// axis-aligned box by two collision passes at fixed points of the step.
//
//  pass one (before the velocity update): a particle outside the box has the
//    outward component of its velocity reflected and scaled by the
//    restitution e ∈ [0, 1]: v_n ← −e·v_n;
//  pass two (after the position update): a particle that is outside now and
//    was also outside before the position update is projected back onto the
//    box (its coordinates clamped to [lo, hi]).
//
// A particle that crosses a wall during one position update is therefore left
// up to |v|·Δt + ½|a|·Δt² outside until the next step: the thesis's behaviour.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "swirl/core/box.hpp"
#include "swirl/core/particle_set.hpp"

namespace swirl::boundary {

template <class Real>
struct BoxCollision {
  Box<Real> box;
  Real restitution = Real(0.5);  // e, in [0, 1]

  // True when particle i lies outside the box.
  bool outside(const ParticleSet<Real>& p, std::size_t i) const {
    return !box.contains(p.position.get(i));
  }

  // Pass one for particles [begin, end).
  void reflect_velocities(ParticleSet<Real>& p, std::size_t begin, std::size_t end) const {
    for (int axis = 0; axis < 3; ++axis) {
      const Real* x = p.position[axis].data();
      Real* v = p.velocity[axis].data();
      const Real lo = box.lo[axis], hi = box.hi[axis], e = restitution;
#pragma omp simd
      for (std::size_t i = begin; i < end; ++i) {
        const bool outward = (x[i] < lo && v[i] < Real(0)) || (x[i] > hi && v[i] > Real(0));
        v[i] = outward ? -e * v[i] : v[i];
      }
    }
  }

  // Pass two for one particle that was outside before the position update.
  void project_if_outside(ParticleSet<Real>& p, std::size_t i) const {
    if (!outside(p, i)) return;
    for (int axis = 0; axis < 3; ++axis) {
      Real& x = p.position[axis][i];
      x = std::clamp(x, box.lo[axis], box.hi[axis]);
    }
  }
};

}  // namespace swirl::boundary
