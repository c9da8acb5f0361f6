// Probes of an SPH fluid (docs/sph.md, Probes): the quantities probes.csv
// records at named points and vertical lines, from the particles alone.
//
//   pressure at x   p(x) = Σ_j V_j p_j W(x − x_j) / Σ_j V_j W(x − x_j)
//                   over the fluid particles j within h (V_j = m_j/ρ_j):
//                   the Shepard-normalised kernel interpolation, which stays
//                   unbiased near a wall or the free surface where the kernel
//                   is cut; 0 (the gauge pressure of air) with no fluid within h.
//   colour at x     c(x) = Σ_j V_j W(x − x_j): ≈ 1 inside the fluid, ½ on a
//                   flat free surface (a half-space of the kernel), 0 outside.
//   water height    along a vertical line from z0 to z1, sampled every h/8:
//                   the highest z where c(z) ≥ ½ (linear between the samples
//                   around the crossing), as z − z0; 0 when no sample
//                   reaches ½, z1 − z0 when the top one does. A lone particle
//                   never reaches ½ (its own V W(0) is 0.34 for the cubic
//                   spline at h = 1.95 spacings, 0.21 for poly6), so single
//                   droplets above the water do not count; a sheet does.
//
// W is the fluid's density kernel (poly6 for the thesis's solver, sph.kernel
// with DFSPH) at its h. Boundary particles are left out of both sums. Every
// sum runs serially in memory order in double: the same bits for any thread
// count (the order is the simulation's, which a resume restores).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "swirl/core/particle_kind.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/sph/laws.hpp"
#include "swirl/sph/parameters.hpp"

namespace swirl::sph {

class ProbeSampler {
 public:
  // The level of the colour field that is the free surface.
  static constexpr double kSurfaceColour = 0.5;

  explicit ProbeSampler(const SphParameters& params)
      : kernel_(params.method == SphMethod::Dfsph ? params.kernel : SphKernel::Thesis, params.smoothing_length) {}

  double h() const { return kernel_.h; }

  // p(x), Pa (see the header).
  template <class Real>
  double pressure(const ParticleSet<Real>& p, const Vec3d& at) const {
    const std::int32_t* kind = kinds(p);
    double weighted = 0, weights = 0;
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (kind && is_boundary(kind[j])) continue;
      const double w = weight(p, j, at);
      if (w == 0) continue;
      weighted += w * double(p.pressure[j]);
      weights += w;
    }
    return weights > 0 ? weighted / weights : 0.0;
  }

  // c(x) (see the header).
  template <class Real>
  double colour(const ParticleSet<Real>& p, const Vec3d& at) const {
    const std::int32_t* kind = kinds(p);
    double c = 0;
    for (std::size_t j = 0; j < p.size(); ++j)
      if (!kind || !is_boundary(kind[j])) c += weight(p, j, at);
    return c;
  }

  // The water height above `lower` along the vertical line to `upper`, m (see the header).
  template <class Real>
  double height(const ParticleSet<Real>& p, const Vec3d& lower, const Vec3d& upper) const {
    const double h = kernel_.h, length = upper.z - lower.z;
    // The fluid particles that can reach the line: within h of its axis and its ends.
    const std::int32_t* kind = kinds(p);
    near_.clear();
    for (std::size_t j = 0; j < p.size(); ++j)
      if ((!kind || !is_boundary(kind[j])) && reaches_line(p, j, lower, upper)) near_.push_back(j);
    if (near_.empty() || !(length > 0)) return 0.0;
    const auto samples = static_cast<std::size_t>(std::min(std::ceil(length / (h / 8)), 1e6));
    const double step = length / static_cast<double>(samples);
    auto colour_at = [&](std::size_t k) {
      const Vec3d at{lower.x, lower.y, lower.z + step * static_cast<double>(k)};
      double c = 0;
      for (const std::size_t j : near_) c += weight(p, j, at);
      return c;
    };
    double above = colour_at(samples);  // the sample above the one looked at
    if (above >= kSurfaceColour) return length;
    for (std::size_t k = samples; k-- > 0;) {
      const double c = colour_at(k);
      if (c >= kSurfaceColour)
        return step * (static_cast<double>(k) + (c - kSurfaceColour) / (c - above));
      above = c;
    }
    return 0.0;
  }

  // Whether particle j can add to a sum at the point `at`: its weight there
  // is not 0 only if this holds (within h). On several ranks these choose
  // the particles sent to the rank that writes probes.csv (sim/probe_log.hpp).
  template <class Real>
  bool reaches_point(const ParticleSet<Real>& p, std::size_t j, const Vec3d& at) const {
    return distance2(p, j, at) < kernel_.h2;
  }
  // Whether particle j is among the particles height() samples along the
  // line from `lower` to `upper`: within h of its axis and of its ends.
  template <class Real>
  bool reaches_line(const ParticleSet<Real>& p, std::size_t j, const Vec3d& lower, const Vec3d& upper) const {
    const double h = kernel_.h;
    const double dx = double(p.position.x[j]) - lower.x, dy = double(p.position.y[j]) - lower.y;
    const double z = double(p.position.z[j]);
    return dx * dx + dy * dy < h * h && z > lower.z - h && z < upper.z + h;
  }

 private:
  template <class Real>
  static double distance2(const ParticleSet<Real>& p, std::size_t j, const Vec3d& at) {
    const double dx = at.x - double(p.position.x[j]), dy = at.y - double(p.position.y[j]),
                 dz = at.z - double(p.position.z[j]);
    return dx * dx + dy * dy + dz * dz;
  }

  template <class Real>
  static const std::int32_t* kinds(const ParticleSet<Real>& p) {
    const std::size_t k = p.find_int_field(kKindField);
    return k == ParticleSet<Real>::npos ? nullptr : p.int_field(k).data();
  }

  // V_j W(x − x_j), 0 beyond h.
  template <class Real>
  double weight(const ParticleSet<Real>& p, std::size_t j, const Vec3d& at) const {
    const double r2 = distance2(p, j, at);
    if (!(r2 < kernel_.h2)) return 0.0;
    const double rho = double(p.density[j]);
    if (!(rho > 0)) return 0.0;
    return double(p.mass[j]) / rho * kernel_.w(r2, std::sqrt(r2));
  }

  DfsphKernel<double> kernel_;
  mutable std::vector<std::size_t> near_;  // height(): the particles near the line (scratch)
};

}  // namespace swirl::sph
