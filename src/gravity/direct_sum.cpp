#include "swirl/gravity/direct_sum.hpp"

#include <cmath>
#include <stdexcept>

#include "swirl/gravity/pair_law.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {
// Adds the pair law over j ∈ [begin, end) to the sums of the particle at (x, y, z).
template <class Real>
void sum_range(const Real* px, const Real* py, const Real* pz, const Real* m, std::size_t begin, std::size_t end,
               Real x, Real y, Real z, Real eps2, Accumulator<Real>& out) {
  Real ax = 0, ay = 0, az = 0, phi = 0;
#pragma omp simd reduction(+ : ax, ay, az, phi)
  for (std::size_t j = begin; j < end; ++j) {
    const Real dx = px[j] - x, dy = py[j] - y, dz = pz[j] - z;
    const PairTerm<Real> t = pair_term(dx, dy, dz, m[j], eps2);
    ax += t.accel * dx;
    ay += t.accel * dy;
    az += t.accel * dz;
    phi += t.potential;
  }
  out.ax += ax;
  out.ay += ay;
  out.az += az;
  out.phi += phi;
}
}  // namespace

template <class Real>
void direct_sum(const ParticleSet<Real>& p, Real softening, std::size_t block_size, GravityField<Real>& out,
                const ActiveSet& active) {
  if (!(softening >= 0 && std::isfinite(softening)))
    throw std::invalid_argument("direct_sum: softening epsilon must be finite and >= 0");
  const std::size_t n = p.size();
  out.resize(n);
  const Real eps2 = softening * softening;
  const Real *px = p.position.x.data(), *py = p.position.y.data(), *pz = p.position.z.data(), *m = p.mass.data();
  parallel::for_blocks("gravity_direct_sum", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t i = b; i < e; ++i) {
      if (!active.contains(i)) continue;
      // a_i = Σ_{j≠i} m_j (x_j − x_i) / (|r|² + ε²)^{3/2}, φ_i = −Σ_{j≠i} m_j / sqrt(|r|² + ε²)
      Accumulator<Real> acc;
      sum_range(px, py, pz, m, 0, i, px[i], py[i], pz[i], eps2, acc);
      sum_range(px, py, pz, m, i + 1, n, px[i], py[i], pz[i], eps2, acc);
      out.acceleration.x[i] = acc.ax;
      out.acceleration.y[i] = acc.ay;
      out.acceleration.z[i] = acc.az;
      out.potential[i] = acc.phi;
    }
  });
}

template void direct_sum<float>(const ParticleSet<float>&, float, std::size_t, GravityField<float>&,
                                const ActiveSet&);
template void direct_sum<double>(const ParticleSet<double>&, double, std::size_t, GravityField<double>&,
                                 const ActiveSet&);

}  // namespace swirl::gravity
