// Particle mass for fluid on a simple cubic lattice, and the smoothing length
// for a target neighbour count.
#pragma once

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "swirl/sph/kernels.hpp"
#include "swirl/sph/parameters.hpp"

namespace swirl::sph {

// The mass m that makes the SPH density of an interior particle of a simple
// cubic lattice of spacing s exactly ρ0: m = ρ0 / Σ_n W_poly6(|n|·s, h), the sum
// over all lattice vectors n (the particle itself included) within h. A block
// made with it starts at rest with zero pressure inside. With the cubic spline
// (DFSPH's kernel, sph.kernel) the sum is of that kernel's W.
inline double lattice_mass_for_density(double spacing, double h, double rest_density,
                                       SphKernel kernel = SphKernel::Thesis) {
  if (!(spacing > 0) || !(h > 0) || !(rest_density > 0) || h / spacing > 1000)
    throw std::invalid_argument("lattice mass: need spacing > 0, h > 0, ρ0 > 0 and h/spacing ≤ 1000");
  const Poly6<double> w(h);
  const CubicSpline<double> cubic(h);
  const int reach = static_cast<int>(std::ceil(h / spacing));
  double sum = 0;
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j)
      for (int k = -reach; k <= reach; ++k) {
        const double r2 = spacing * spacing * double(i * i + j * j + k * k);
        sum += kernel == SphKernel::CubicSpline ? cubic(std::sqrt(r2)) : w(r2);
      }
  return rest_density / sum;
}

// The h whose ball holds k neighbours on average when each particle occupies
// volume v: (4/3)π h³ = (k + 1)·v counts the particle itself, so
// h = (3 (k + 1) v / (4π))^(1/3). Self is not a neighbour (section 4.2).
// Boundary particles (Akinci et al. 2012): the distance d from a plane layer
// of boundary particles (a square lattice of spacing `spacing`, each of volume
// weight ψ = ρ0/Σ_k W over the layer) at which the first layer of a fluid
// lattice of the same spacing, filling the half-space beyond it, has exactly
// the rest density: ρ = (the fluid's half-space, its own layer included) +
// Σ_b ψ W(r_ib) = ρ0. For the cubic spline at h = 1.95 spacings d = 1.09
// spacings, for poly6 1.13 (at d = 1 spacing the layer over-fills by 5.5 % and
// 10 %, which DFSPH's first step removes with a jet). Found by bisection in
// [0.3, 3] spacings; the density falls with d there.
inline double wall_distance_for_density(double spacing, double h, SphKernel kernel = SphKernel::Thesis) {
  if (!(spacing > 0) || !(h > 0) || h / spacing > 1000)
    throw std::invalid_argument("wall distance: need spacing > 0, h > 0 and h/spacing ≤ 1000");
  const Poly6<double> poly6(h);
  const CubicSpline<double> cubic(h);
  const auto w = [&](double r2) { return kernel == SphKernel::CubicSpline ? cubic(std::sqrt(r2)) : poly6(r2); };
  const int reach = static_cast<int>(std::ceil(h / spacing)) + 1;
  double full = 0, half = 0, layer = 0;
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j) {
      layer += w(spacing * spacing * double(i * i + j * j));
      for (int k = -reach; k <= reach; ++k) {
        const double term = w(spacing * spacing * double(i * i + j * j + k * k));
        full += term;
        if (k >= 0) half += term;
      }
    }
  // In units of ρ0: the fluid's mass per particle is 1/full, the layer's ψ is 1/layer.
  const auto density = [&](double d) {
    double sheet = 0;
    for (int i = -reach; i <= reach; ++i)
      for (int j = -reach; j <= reach; ++j) sheet += w(spacing * spacing * double(i * i + j * j) + d * d);
    return half / full + sheet / layer;
  };
  double lo = 0.3 * spacing, hi = 3 * spacing;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (density(mid) > 1 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

inline double smoothing_length_for_neighbours(double neighbours, double volume_per_particle) {
  if (!(neighbours > 0) || !(volume_per_particle > 0))
    throw std::invalid_argument("smoothing length: need neighbours > 0 and a positive particle volume");
  return std::cbrt(3.0 * (neighbours + 1.0) * volume_per_particle / (4.0 * std::numbers::pi));
}

}  // namespace swirl::sph
