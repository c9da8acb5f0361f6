// A disk galaxy: an exponential stellar disk in a live Hernquist halo, set up
// by Hernquist's (1993, ApJS 86, 389) recipe so that the disk stays a disk.
// Conventions as in initial_conditions.hpp: G = 1, seeded with SplitMix64
// (the same particles on every machine), ids 0..N−1, std::invalid_argument
// for a parameter out of range. docs/gravity.md has the formulas and sources.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swirl/core/particle_set.hpp"

namespace swirl::gravity {

// The disk: Σ(R) = M_d/(2π h²) e^{−R/h} out to R = disk_cut·h (the particles
// carry M_d), ρ(R, z) = Σ(R)/(2z₀) sech²(z/z₀). Its velocities are Gaussian
// about moments from the Jeans equations in the epicyclic approximation
// (Hernquist 1993, §2.2.3): σ_R ∝ e^{−R/2h} with Toomre's Q = σ_R κ/(3.36 GΣ) =
// toomre_q at R = 2.43 h; σ_φ² = σ_R² κ²/(4Ω²); mean rotation v̄_φ² = V_c² +
// σ_R²(1 − κ²/(4Ω²) − 2R/h) (asymmetric drift; 0 where that is negative, near
// the centre), V_c and κ from the midplane field of the sech² disk (a Hankel
// transform: Freeman's (1970) razor-thin disk would spin it too fast, by 4 %
// of V_c² at h and 2 % at 2h) and the halo; σ_z² from the vertical Jeans equation averaged
// over the sech² profile, πGΣz₀ (Hernquist's isothermal sheet) plus the
// halo's pull (π²z₀²/12) G M_h(<R)/R³, which Hernquist left out and which is
// not small for a light disk (without it this galaxy's disk is squeezed and
// breathes). The halo: Hernquist (1990), ρ = M_h a/(2π r (r + a)³), M_h =
// 1 − M_d, radii from its mass profile up to halo_mass_cut of it (particles
// carry M_h·cut, so inside the cut the halo is exactly the model's),
// isotropic velocities from the distribution function computed by
// Eddington's formula in the total potential, the disk's taken spherical (its
// mass M_d[1 − (1 + r/h)e^{−r/h}] within r), so the halo is in equilibrium
// with the disk inside it. The halo's particles come first (ids 0..N_h − 1),
// then the disk's; the cusp at the origin, the disk in the z = 0 plane
// rotating about +z, the centre-of-mass velocity removed. Units: G = 1,
// M_h + M_d = 1, lengths in the halo's scale radius by default. Defaults: a
// light disk, h = a/5, dominated by the halo (Efstathiou, Lake & Negroponte
// 1982's V_max/√(GM_d/h) = 1.38 > 1.1: no bar), with as many disk as halo
// particles, as Hernquist (1993) had; a rotation at the disk's half-mass
// radius (1.68 h) takes 4.5.
struct DiskGalaxyOptions {
  double disk_mass = 0.03;          // M_d, in (0, 1)
  double disk_scale_length = 0.2;   // h > 0
  double disk_scale_height = 0.04;  // z₀ > 0 (ρ ∝ sech²(z/z₀))
  double disk_cut = 10;             // the disk's radius in scale lengths, in [2, 50]
  double toomre_q = 1.5;            // Q at R = 2.43 h, > 0
  double halo_scale_radius = 1;     // a > 0
  double halo_mass_cut = 0.99;      // in (0, 1)
  double disk_particles = 0.5;      // the disk's share of the N particles, in (0, 1)
};
template <class Real>
ParticleSet<Real> disk_galaxy(std::size_t n, std::uint64_t seed, const DiskGalaxyOptions& options = {});

// The disk's velocity moments at cylindrical radii R > 0 (the prescription
// disk_galaxy() samples from) and its surface density there; one table of
// the disk's rotation serves all the radii.
struct DiskKinematics {
  double circular_speed = 0;  // V_c, midplane, disk + halo
  double epicyclic = 0;       // κ
  double sigma_r = 0, sigma_phi = 0, sigma_z = 0;
  double mean_rotation = 0;   // v̄_φ
  double surface_density = 0; // Σ of the sampled (cut) disk
};
std::vector<DiskKinematics> disk_kinematics(const std::vector<double>& radii, const DiskGalaxyOptions& options = {});

extern template ParticleSet<float> disk_galaxy<float>(std::size_t, std::uint64_t, const DiskGalaxyOptions&);
extern template ParticleSet<double> disk_galaxy<double>(std::size_t, std::uint64_t, const DiskGalaxyOptions&);

}  // namespace swirl::gravity
