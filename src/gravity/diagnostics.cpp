#include "swirl/gravity/diagnostics.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {
template <class Real>
const Real* potential_field(const ParticleSet<Real>& p) {
  for (const auto& f : p.fields())
    if (f.name == "potential" && f.components == 1) return f.data[0];
  throw std::invalid_argument("gravity diagnostics: the particles have no \"potential\" field; "
                              "evaluate the gravity force first");
}

struct Sums {
  double m = 0, k = 0, w = 0;
  Vec3d p{}, l{}, mx{};
  friend Sums operator+(Sums a, const Sums& b) {
    a.m += b.m;
    a.k += b.k;
    a.w += b.w;
    a.p += b.p;
    a.l += b.l;
    a.mx += b.mx;
    return a;
  }
};
}  // namespace

template <class Real>
Diagnostics diagnose(const ParticleSet<Real>& p, std::size_t block_size) {
  const Real* phi = potential_field(p);
  const Sums s = parallel::reduce_blocks(
      "gravity_diagnostics", p.size(), block_size, Sums{},
      [&](std::size_t b, std::size_t e) {
        Sums part;
        for (std::size_t i = b; i < e; ++i) {
          const double m = p.mass[i];
          const Vec3d x = p.position.get(i).template cast<double>();
          const Vec3d v = p.velocity.get(i).template cast<double>();
          part.m += m;
          part.k += 0.5 * m * dot(v, v);  // K = ½ Σ m |v|²
          part.w += 0.5 * m * phi[i];     // W = ½ Σ m φ
          part.p += m * v;                // P = Σ m v
          part.l += m * cross(x, v);      // L = Σ m x × v
          part.mx += m * x;
        }
        return part;
      },
      [](const Sums& a, const Sums& b) { return a + b; });
  Diagnostics d;
  d.mass = s.m;
  d.kinetic = s.k;
  d.potential = s.w;
  d.total = s.k + s.w;
  d.virial_ratio = s.w != 0 ? 2 * s.k / std::abs(s.w) : 0.0;
  d.momentum = s.p;
  d.angular_momentum = s.l;
  d.centre_of_mass = s.m != 0 ? s.mx * (1 / s.m) : Vec3d{};
  return d;
}

template <class Real>
double potential_energy(const ParticleSet<Real>& p, const dist::BlockFold& fold) {
  const Real* phi = potential_field(p);
  return fold.sum("gravity_potential_energy", p.size(),
                  [&](std::size_t i) { return 0.5 * double(p.mass[i]) * double(phi[i]); });  // W = ½ Σ m φ
}

template <class Real>
double virial_ratio(const ParticleSet<Real>& p, const dist::BlockFold& fold) {
  const Real* phi = potential_field(p);
  const auto kw = fold("gravity_virial", p.size(), std::array{dist::FoldOp::Sum, dist::FoldOp::Sum},
                       [&](std::size_t i, std::array<double, 2>& c) {
                         const double m = p.mass[i];
                         const Vec3d v = p.velocity.get(i).template cast<double>();
                         c[0] = 0.5 * m * dot(v, v);     // K
                         c[1] = 0.5 * m * double(phi[i]);  // W
                         return true;
                       });
  return kw[1] != 0 ? 2 * kw[0] / std::abs(kw[1]) : 0.0;
}

template Diagnostics diagnose<float>(const ParticleSet<float>&, std::size_t);
template Diagnostics diagnose<double>(const ParticleSet<double>&, std::size_t);
template double potential_energy<float>(const ParticleSet<float>&, const dist::BlockFold&);
template double potential_energy<double>(const ParticleSet<double>&, const dist::BlockFold&);
template double virial_ratio<float>(const ParticleSet<float>&, const dist::BlockFold&);
template double virial_ratio<double>(const ParticleSet<double>&, const dist::BlockFold&);

}  // namespace swirl::gravity
