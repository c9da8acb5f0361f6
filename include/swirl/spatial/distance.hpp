// The one rule that decides whether two particles interact: j ≠ i and
// r² = |x_i − x_j|² < h². Every neighbour search (hash, brute force) calls this,
// so fast and slow paths agree on every borderline pair.
#pragma once

namespace swirl::spatial {

// Squared distance between (xi, yi, zi) and (xj, yj, zj), evaluated in one fixed
// order so that every caller gets the same bits.
template <class Real>
inline Real distance2(Real xi, Real yi, Real zi, Real xj, Real yj, Real zj) {
  const Real dx = xi - xj, dy = yi - yj, dz = zi - zj;
  return dx * dx + dy * dy + dz * dz;
}

// True when a pair at squared distance r2 interacts for support radius² h2.
template <class Real>
inline bool within(Real r2, Real h2) { return r2 < h2; }

}  // namespace swirl::spatial
