// Interaction kernels of the group walk: the field of a list of sources
// (particles, or cells with their multipole expansions) added to every
// particle of a group, over structure-of-arrays data.
//
// Laws (G = 1, Plummer softening ε, eps2 = ε²; d = source − target):
//   particle  the pair law of pair_law.hpp (add_point): a += m d / (|d|² + ε²)^{3/2},
//             φ −= m / sqrt(|d|² + ε²); a pair at zero softened distance
//             contributes nothing;
//   monopole  the same law with the cell's mass at its centre of mass;
//   quadrupole (added to the monopole if asked) with the traceless
//             Q_ij = Σ m (3 r_i r_j − r² δ_ij) about the centre of mass
//             (qzz = −qxx − qyy), r = target − centre of mass:
//             φ −= ½ rᵀQr / R⁵, a = −∇φ, R = sqrt(|r|² + ε²)
//             (pair_law.hpp's add_cell, which LinearOctree::walk_one calls too).
// The field is ADDED to the targets' ax, ay, az, phi.
//
// Two paths of the same formulas:
//   KernelPath::Scalar  a plain loop, target by target, sources in order: the
//                       reference the SIMD path is tested against;
//   KernelPath::Simd    explicit SIMD (xsimd) compiled per instruction set and
//                       picked at run time (core/simd_dispatch.hpp): targets
//                       across the lanes of a batch, each source broadcast to
//                       all lanes (the last < W targets, if the list is
//                       long, sources across the lanes with horizontal sums:
//                       see interaction_kernels_simd.cpp). 1/sqrt: for float
//                       the hardware estimate (rsqrt14 with AVX-512, rsqrt
//                       below) and one Newton step (relative error ≲ 3e-7
//                       per term); for double with AVX-512 rsqrt14 and two
//                       Newton steps (~1 ulp), else an exact square root and
//                       division.
// The SIMD results equal the scalar ones to round-off (not bitwise: the
// summation order and the 1/sqrt differ) and depend only on the inputs and
// the instruction set — never on threads (the kernels are pure functions of
// their arguments). Arrays are read only up to n; no alignment is required.
// Range: |d|² + ε² finite and, where nonzero, a normal number (in float with
// ε = 0: pairs closer than ~1e-19 are outside the SIMD path's range; the
// scalar path overflows there too).
//
// Units: as the inputs (lengths as positions, masses as given, G = 1).
#pragma once

#include <cstddef>

#include "swirl/core/kernel_path.hpp"

namespace swirl::gravity {

// Particle–particle sources (SoA).
template <class Real>
struct SourceParticles {
  const Real *x, *y, *z, *m;
  std::size_t n;
  // If not npos: source self_offset + t IS target t (the group's own
  // particles) and that pair is skipped.
  std::size_t self_offset = npos;

  static constexpr std::size_t npos = std::size_t(-1);
};

// Cell sources: centre of mass, mass, traceless quadrupole (qzz = −qxx − qyy).
// The q* pointers may be null when the kernel is called without quadrupole.
template <class Real>
struct SourceCells {
  const Real *x, *y, *z, *m, *qxx, *qxy, *qxz, *qyy, *qyz;
  std::size_t n;
};

// The group's particles; the field is ADDED to ax, ay, az, phi.
template <class Real>
struct Targets {
  const Real *x, *y, *z;
  Real *ax, *ay, *az, *phi;
  std::size_t n;
};

// Adds the pair-law field of every source particle to every target.
template <class Real>
void add_particle_field(const SourceParticles<Real>& s, const Targets<Real>& t, Real eps2,
                        KernelPath path = KernelPath::Simd);

// Adds the monopole field of every cell, plus its quadrupole term if `quadrupole`.
template <class Real>
void add_cell_field(const SourceCells<Real>& s, const Targets<Real>& t, Real eps2, bool quadrupole,
                    KernelPath path = KernelPath::Simd);

// Flops per interaction (one source on one target), for FLOP/s figures.
// Convention: the operations of the textbook formulas below (the monopole,
// then the quadrupole term added to it), an add, a multiply or a subtraction
// 1 flop, a fused multiply-add 2, a square root 1 and a division 1 (so
// 1/sqrt = 2, whatever the instruction sequence that computes it: the float
// SIMD path's rsqrt + Newton step does more work, counted as 2); selects and
// compares 0; work done once per source for all targets (qzz = −qxx − qyy)
// not counted.
//   particle / monopole: d (3) + |d|² + ε² (6) + 1/sqrt (2) + m/R, m/R³ (3)
//                        + a += (m/R³) d (6) + φ −= m/R (1)             = 21
//   quadrupole (total, monopole included): 21 + Q·r (15) + rᵀQr (5)
//                        + 1/R⁵, 1/R⁷ (3) + 2.5 rᵀQr/R⁷ (2)
//                        + a += radial r − Qr/R⁵ (12) + φ −= ½ rᵀQr/R⁵ (3) = 61
// pair_law.hpp's add_cell, which every path evaluates, shares one radial
// coefficient between the monopole and the quadrupole and does 55 by this
// count; the figure stays 61 so that FLOP/s stay comparable with earlier records.
inline constexpr int kParticleFlops = 21;
inline constexpr int kMonopoleFlops = 21;
inline constexpr int kQuadrupoleFlops = 61;

extern template void add_particle_field<float>(const SourceParticles<float>&, const Targets<float>&, float,
                                               KernelPath);
extern template void add_particle_field<double>(const SourceParticles<double>&, const Targets<double>&, double,
                                                KernelPath);
extern template void add_cell_field<float>(const SourceCells<float>&, const Targets<float>&, float, bool,
                                           KernelPath);
extern template void add_cell_field<double>(const SourceCells<double>&, const Targets<double>&, double, bool,
                                            KernelPath);

}  // namespace swirl::gravity
