// GravityField<Real>: what a gravity evaluation produces for every particle,
// indexed like the ParticleSet it was computed from.
//
//   acceleration  a_i = Σ_j m_j (x_j − x_i) / (|r|² + ε²)^{3/2}   (G = 1)
//   potential     φ_i = −Σ_j m_j / sqrt(|r|² + ε²), j ≠ i; W = ½ Σ m_i φ_i
#pragma once

#include <cstddef>

#include "swirl/core/aligned.hpp"
#include "swirl/core/particle_set.hpp"

namespace swirl::gravity {

template <class Real>
struct GravityField {
  Vec3Array<Real> acceleration;
  AlignedVector<Real> potential;

  std::size_t size() const { return potential.size(); }
  void resize(std::size_t n) {
    acceleration.x.resize(n);
    acceleration.y.resize(n);
    acceleration.z.resize(n);
    potential.resize(n);
  }
};

}  // namespace swirl::gravity
