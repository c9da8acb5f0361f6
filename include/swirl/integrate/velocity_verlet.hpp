// Velocity Verlet, the thesis's integrator (section 4.4, eq. 4.1 and 4.2):
//
//   r(t + Δt) = r(t) + v(t)·Δt + ½·a(t)·Δt²                  (4.2)  drift()
//   v(t + Δt) = v(t) + ½·(a(t) + a(t + Δt))·Δt               (4.1)  kick()
//
// split into the two per-particle updates the step loop calls around the force
// evaluation (see sim/simulation.hpp for their order). drift() also saves a(t)
// as acceleration_prev, which kick() needs once a(t + Δt) is known. Both are
// exact for a constant acceleration.
#pragma once

#include <cstddef>

#include "swirl/core/particle_set.hpp"

namespace swirl::integrate {

// Advances the positions of particles [begin, end) by dt (eq. 4.2) and sets
// acceleration_prev = acceleration.
template <class Real>
inline void drift(ParticleSet<Real>& p, std::size_t begin, std::size_t end, Real dt) {
  const Real half_dt2 = Real(0.5) * dt * dt;
  for (int axis = 0; axis < 3; ++axis) {
    Real* x = p.position[axis].data();
    const Real* v = p.velocity[axis].data();
    Real* a = p.acceleration[axis].data();
    Real* a_prev = p.acceleration_prev[axis].data();
#pragma omp simd
    for (std::size_t i = begin; i < end; ++i) {
      x[i] += v[i] * dt + a[i] * half_dt2;
      a_prev[i] = a[i];
    }
  }
}

// Completes the velocities of particles [begin, end) (eq. 4.1) once
// acceleration holds a(t + Δt) and acceleration_prev holds a(t).
template <class Real>
inline void kick(ParticleSet<Real>& p, std::size_t begin, std::size_t end, Real dt) {
  const Real half_dt = Real(0.5) * dt;
  for (int axis = 0; axis < 3; ++axis) {
    Real* v = p.velocity[axis].data();
    const Real* a = p.acceleration[axis].data();
    const Real* a_prev = p.acceleration_prev[axis].data();
#pragma omp simd
    for (std::size_t i = begin; i < end; ++i) v[i] += (a_prev[i] + a[i]) * half_dt;
  }
}

}  // namespace swirl::integrate
