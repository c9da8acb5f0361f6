// Spherical equilibrium models whose distribution function is computed
// numerically: the NFW halo of cosmological simulations and the King (1966)
// star cluster. Conventions as in initial_conditions.hpp: G = 1, total mass
// M = 1, seeded with SplitMix64 (the same particles on every machine), ids
// 0..N−1, equal masses 1/N, std::invalid_argument for N = 0 or a parameter
// out of range. docs/gravity.md has the formulas and sources.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "swirl/core/particle_set.hpp"

namespace swirl::gravity {

// Navarro, Frenk & White (1996, 1997) halo, ρ ∝ 1/(x (1 + x)²) with x = r/r_s,
// out to the virial radius r_vir = c·r_s, where its logarithmically divergent
// mass is cut off smoothly as Kazantzidis, Magorrian & Moore (2004, ApJ 601,
// 37, eq. 2) do: beyond r_vir,
//   ρ(r) = ρ(r_vir) (r/r_vir)^κ exp(−(r − r_vir)/r_d),  κ = −(1 + 3c)/(1 + c) + r_vir/r_d,
// which keeps ρ and d ln ρ/d ln r continuous, so the isotropic distribution
// function exists (a sharp cut would need a negative one). The particles
// carry the whole model, tail included (M = 1; the mass inside r_vir is
// slightly less). Radii from the tabulated mass profile; speeds from f(ε)
// computed by Eddington's inversion of the model's own ρ(Ψ) (docs/gravity.md);
// the cusp at the origin and the centre-of-mass velocity removed (the tail's
// sampling noise moves the centre of mass slightly off the cusp, as for
// hernquist()). Lengths: r_vir = virial_radius if set, otherwise scaled so
// that E = −1/4 (Hénon units; r_vir = 1.96 for c = 10).
struct NfwOptions {
  double concentration = 10;              // c = r_vir/r_s, in [1, 100]
  double decay = 0.1;                     // r_d/r_vir, in [0.01, 1]
  std::optional<double> virial_radius{};  // r_vir > 0; unset: Hénon units (E = −1/4)
};
template <class Real>
ParticleSet<Real> nfw(std::size_t n, std::uint64_t seed, const NfwOptions& options = {});

// King (1966, AJ 71, 64) model: the lowered isothermal sphere with
// distribution function f(ε) ∝ exp(ε/σ²) − 1 for binding energy ε > 0 (0
// otherwise), the relative potential Ψ zero at the tidal radius r_t. Its
// density ρ(W) ∝ e^W erf(√W) − √(4W/π)(1 + 2W/3), W = Ψ/σ², and Poisson's
// equation in units of the King radius r₀ = √(9σ²/(4πGρ₀)),
//   W″ + (2/r) W′ = −9 ρ(W)/ρ(W₀),  W(0) = W₀, W′(0) = 0,
// are integrated outward (RK4 in ln r) to W(r_t) = 0. Radii from the solved
// mass profile, speeds by rejection from v² (exp(W − v²/2) − 1); centre of
// mass position and velocity removed; scaled to Hénon units (G = M = 1,
// E = −1/4: for W₀ = 6, r₀ ≈ 0.3 and r_t ≈ 5.4).
struct KingOptions {
  double w0 = 6;  // W₀ = Ψ(0)/σ², the dimensionless central potential, in [0.1, 16]
};
template <class Real>
ParticleSet<Real> king(std::size_t n, std::uint64_t seed, const KingOptions& options = {});

// The scales of a King model in Hénon units, for users and tests: the King
// radius r₀, the tidal radius r_t (concentration log₁₀(r_t/r₀)), the
// central one-dimensional dispersion parameter σ and the half-mass radius.
struct KingScales {
  double king_radius = 0, tidal_radius = 0, sigma = 0, half_mass_radius = 0;
};
KingScales king_scales(const KingOptions& options = {});

extern template ParticleSet<float> nfw<float>(std::size_t, std::uint64_t, const NfwOptions&);
extern template ParticleSet<double> nfw<double>(std::size_t, std::uint64_t, const NfwOptions&);
extern template ParticleSet<float> king<float>(std::size_t, std::uint64_t, const KingOptions&);
extern template ParticleSet<double> king<double>(std::size_t, std::uint64_t, const KingOptions&);

}  // namespace swirl::gravity
