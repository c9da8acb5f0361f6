// Initial conditions for gravity runs, in Hénon units (G = 1, total mass M = 1
// unless stated), seeded and reproducible on every machine (SplitMix64, no
// std:: distributions). Every function returns particles with ids 0..N−1,
// positions, velocities and masses set, other fields zero, and throws
// std::invalid_argument for N = 0 or a parameter outside its range.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "swirl/core/particle_set.hpp"

namespace swirl::gravity {

// Plummer scale radius in Hénon units (E = −1/4): a = 3π/16.
inline constexpr double kPlummerScale = 3.0 * 3.14159265358979323846 / 16.0;
// Crossing time in Hénon units: 2√2.
inline constexpr double kHenonCrossingTime = 2.8284271247461900976;

// Plummer sphere by the Aarseth–Hénon–Wielen (1974) recipe: radius from the
// inverted mass profile m(r) = r³/(r² + a²)^{3/2} with m uniform in
// (0, mass_cut) (the customary cut-off of the far halo), speed q·v_esc with q
// drawn by von Neumann rejection from g(q) = q²(1 − q²)^{7/2}, isotropic
// directions; equal masses 1/N; centre of mass position and velocity removed.
// Virial equilibrium, E = −1/4 for N → ∞ and mass_cut → 1.
struct PlummerOptions {
  double mass_cut = 0.999;  // in (0, 1]
};
template <class Real>
ParticleSet<Real> plummer(std::size_t n, std::uint64_t seed, const PlummerOptions& options = {});

// Hernquist (1990, ApJ 356, 359) halo: density ρ(r) = M a / (2π r (r + a)³),
// enclosed mass M r²/(r + a)², potential −GM/(r + a). Radius from the inverted
// mass profile r = a √m / (1 − √m) with m uniform in (0, mass_cut) (its ρ ∝ r⁻⁴
// tail holds 1 % of the mass beyond 199 a); speed from the isotropic
// distribution function (Hernquist's eq. 17) at that radius, by von Neumann
// rejection of v ∈ (0, v_esc) under a bound found by golden-section search
// (the density of v is unimodal); isotropic directions; equal masses 1/N
// (M = 1 for the particles kept); the cusp at the origin and the centre-of-mass
// velocity removed (the heavy tail moves the centre of mass off the cusp by
// ~√(2 a r_max/3N)). G = M = 1; scale_radius = 1/3 puts the untruncated model
// in Hénon units (E = −GM²/(12a) = −1/4).
struct HernquistOptions {
  double scale_radius = 1.0 / 3.0;  // a > 0
  double mass_cut = 0.99;           // in (0, 1)
};
template <class Real>
ParticleSet<Real> hernquist(std::size_t n, std::uint64_t seed, const HernquistOptions& options = {});

// Uniform sphere of radius R and mass M centred at the origin, at rest.
template <class Real>
ParticleSet<Real> uniform_sphere(std::size_t n, std::uint64_t seed, double radius = 1, double mass = 1);

// Uniform cube of side L and mass M centred at the origin, at rest.
template <class Real>
ParticleSet<Real> uniform_cube(std::size_t n, std::uint64_t seed, double side = 1, double mass = 1);

// Cold collapse: uniform sphere at rest, G = M = R = 1 (W = −3/5, free-fall time π/(2√2)).
template <class Real>
ParticleSet<Real> cold_collapse(std::size_t n, std::uint64_t seed);

// Two Plummer spheres on a collision orbit. Sphere k has mass M_k (fractions f
// and 1 − f of M = 1), round(f·N) and N − round(f·N) particles, and is a Hénon
// Plummer sphere scaled to length M_k^{1/3} and velocity (M_k / M_k^{1/3})^{1/2},
// so both stay in equilibrium with the same mean density and crossing time as
// a unit Plummer sphere. Their centres start `separation` apart, offset by
// `impact_parameter` across the relative velocity, which is along x:
//   r₂ − r₁ = (√(d² − b²), b, 0),   v₂ − v₁ = (−v, 0, 0),
// v = relative_velocity, or the parabolic (zero orbital energy) speed √(2M/d)
// if unset. The pair's centre of mass is at rest at the origin. Defaults:
// equal halves, d = 10 (about 13 virial radii of a half), b = 2, parabolic:
// a point-mass pericentre b²/d = 0.4, so the spheres interpenetrate and merge.
struct CollisionOptions {
  double mass_fraction = 0.5;   // f, in (0, 1)
  double separation = 10;       // d > 0
  double impact_parameter = 2;  // b, in [0, d)
  std::optional<double> relative_velocity;  // v ≥ 0; unset: parabolic
  double mass_cut = 0.999;      // of each sphere, as in PlummerOptions
};
template <class Real>
ParticleSet<Real> plummer_collision(std::size_t n, std::uint64_t seed, const CollisionOptions& options = {});

extern template ParticleSet<float> plummer<float>(std::size_t, std::uint64_t, const PlummerOptions&);
extern template ParticleSet<double> plummer<double>(std::size_t, std::uint64_t, const PlummerOptions&);
extern template ParticleSet<float> hernquist<float>(std::size_t, std::uint64_t, const HernquistOptions&);
extern template ParticleSet<double> hernquist<double>(std::size_t, std::uint64_t, const HernquistOptions&);
extern template ParticleSet<float> uniform_sphere<float>(std::size_t, std::uint64_t, double, double);
extern template ParticleSet<double> uniform_sphere<double>(std::size_t, std::uint64_t, double, double);
extern template ParticleSet<float> uniform_cube<float>(std::size_t, std::uint64_t, double, double);
extern template ParticleSet<double> uniform_cube<double>(std::size_t, std::uint64_t, double, double);
extern template ParticleSet<float> cold_collapse<float>(std::size_t, std::uint64_t);
extern template ParticleSet<double> cold_collapse<double>(std::size_t, std::uint64_t);
extern template ParticleSet<float> plummer_collision<float>(std::size_t, std::uint64_t, const CollisionOptions&);
extern template ParticleSet<double> plummer_collision<double>(std::size_t, std::uint64_t, const CollisionOptions&);

}  // namespace swirl::gravity
