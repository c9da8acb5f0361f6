// Private to the gravity module: the numerical machinery of the spherical
// models whose distribution function is not in closed form (NFW, King, the
// halo of a disk galaxy). A model is tabulated on a radius grid (its tracer's
// enclosed mass and the relative potential Ψ = −Φ, zero at infinity or at the
// tidal radius); radii are drawn from the inverted mass table and speeds by
// rejection from v² f(Ψ − v²/2). Everything here is deterministic: the same
// tables and the same SplitMix64 stream give the same particles on every machine.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "swirl/core/random.hpp"

namespace swirl::gravity::detail {

using V3 = std::array<double, 3>;

// A vector of length r in a uniformly random direction (cos θ and φ uniform).
V3 isotropic_vector(SplitMix64& rng, double r);

// A standard normal deviate by Box–Muller (one of the pair; the other is
// dropped so that each call takes exactly two uniforms).
double normal_deviate(SplitMix64& rng);

// A spherical model on an ascending radius grid (G = 1): the enclosed mass of
// the population that is sampled (the tracer) and the relative potential of
// everything (Ψ > 0, descending).
struct RadialTable {
  std::vector<double> r, mass, psi;

  // The radius holding tracer mass m, 0 < m ≤ mass.back(): linear in
  // (ln m, ln r) between nodes (exact for a power law M ∝ r^p), and below the
  // first node along the power law of the first two.
  double radius_of_mass(double m) const;
  // Ψ(r): linear between nodes; Ψ(r[0]) inside the first node (the potential
  // is flat at the centre of any model whose density is less steep than r⁻²),
  // and mass.back()/r outside the last node (everything is inside it).
  double psi_at(double radius) const;
};

// An isotropic distribution function of the binding energy ε = Ψ − v²/2,
// tabulated at ascending energies, linear between them and falling linearly
// to f(0) = 0 below the first.
struct TabulatedDf {
  std::vector<double> energy, f;
  std::vector<double> running_max;  // max(f[0..m]), filled by eddington()
  double operator()(double e) const;
  // max f on [0, e]: f is linear between nodes, so this is the larger of
  // f(e) and the running maximum of the nodes below e. Non-decreasing in e.
  double majorant(double e) const;
};

// Eddington's (1916) inversion for an isotropic tracer of density ρ in the
// potential Ψ (Binney & Tremaine 2008, eq. 4.46b):
//   f(ε) = 1/(√8 π²) d/dε ∫₀^ε (dρ/dΨ) dΨ / √(ε − Ψ),
// the integral taken with dρ/dΨ linear in Ψ between the table's nodes (so the
// inverse-square-root singularity is integrated exactly, node by node), and
// the derivative by the three-point rule on the nodes' unequal spacing. The
// table's energies are the nodes' Ψ. drho_dpsi[i] is dρ/dΨ at table.r[i]
// (= ρ'(r) r²/(−M_total(r)) for G = 1); below the last node's Ψ it is taken
// to fall linearly to 0 at Ψ = 0, so the grid must reach far enough out that
// the tracer's density there is negligible.
TabulatedDf eddington(const RadialTable& table, const std::vector<double>& drho_dpsi);

// The most negative value of f relative to its largest, to reject models
// (such as a too sharply truncated NFW halo) that no isotropic f can make.
double most_negative_fraction(const TabulatedDf& df);

// A speed at relative potential psi from the density ∝ v² f(psi − v²/2) on
// (0, √(2 psi)), by von Neumann rejection under a piecewise-constant envelope:
// on each of 64 equal bins of x = v/v_esc, x² ≤ x_hi² and f(ε) ≤ majorant(ε_hi),
// where majorant(e) ≥ f on [0, e] and does not decrease (for a non-decreasing
// f, f itself). The envelope is a true bound whatever the shape of f, so the
// sample follows the density exactly. std::invalid_argument if the envelope
// is not finite and positive or 10⁷ proposals fail (tables spoilt by
// overflow: unreachable within the models' ranges).
double sample_speed(SplitMix64& rng, double psi, const std::function<double(double)>& f,
                    const std::function<double(double)>& majorant);

// The potential energy W = −∫ M(r) dM / r of a tabulated model (G = 1), by the
// trapezoidal rule in dM, plus the inner core taken as the first node's M/r.
double potential_energy(const RadialTable& table);

}  // namespace swirl::gravity::detail
