// The explicit-SIMD bodies of the SPH grid passes (sph/grid_passes.hpp), one
// cell at a time, behind runtime dispatch (core/simd_dispatch.hpp).
//
// src/sph/grid_passes_simd.cpp is compiled once per instruction set (SSE2,
// AVX2 + FMA, AVX-512; `generic` off x86-64); the functions below call the copy
// of simd::active(): the widest the CPU runs, or SWIRL_SIMD / simd::ScopedIsa.
// A call handles the particles [first, last) of one cell, which share the
// `count` candidate ranges of the cells around it; every candidate j is
// distance-tested (r² < h², lanes past a range masked), so the pairs are
// exactly the scalar twin's. Arrays are the sorted-order particle fields; the
// argument structs hold plain pointers and the laws (sph/laws.hpp: plain data
// and force-inlined templates, SI units) so that the per-ISA objects define no
// function of a library header.
// Within one instruction set a particle's result depends only on the inputs,
// never on the thread or block that computes it; across instruction sets the
// summation order (batch width, FMA contraction), and so the last bits, differ.
#pragma once

#include <cstddef>
#include <cstdint>

#include "swirl/core/index_range.hpp"
#include "swirl/sph/laws.hpp"

namespace swirl::sph {

// Inputs and outputs of the density pass (grid_density()).
template <class Real>
struct DensityKernelArgs {
  const Real *x = nullptr, *y = nullptr, *z = nullptr, *mass = nullptr;
  Real *density = nullptr, *pressure = nullptr;
  Real *volume = nullptr, *pressure_volume = nullptr;  // m_i / ρ_i and p_i m_i / ρ_i
  std::size_t n = 0;                                   // particles (loads stay below n)
  SphLaws<Real> laws;                                  // density law and equation of state
};

// Inputs and outputs of the force pass (grid_forces()).
template <class Real>
struct ForceKernelArgs {
  const Real *x = nullptr, *y = nullptr, *z = nullptr;
  const Real *vx = nullptr, *vy = nullptr, *vz = nullptr;
  const Real *volume = nullptr, *pressure_volume = nullptr, *pressure = nullptr, *density = nullptr;
  Real *ax = nullptr, *ay = nullptr, *az = nullptr;  // accumulated into (+=)
  const Real* correction[6] = {};  // L_i (xx, xy, xz, yy, yz, zz) when laws.corrected
  std::size_t n = 0;
  SphLaws<Real> laws;  // pressure and viscosity laws
};

// Density and pressure (and the scratch) of particles [first, last); returns
// their neighbour pairs, self excluded.
std::uint64_t density_cell_simd(const DensityKernelArgs<float>& a, std::size_t first, std::size_t last,
                                const IndexRange* ranges, int count);
std::uint64_t density_cell_simd(const DensityKernelArgs<double>& a, std::size_t first, std::size_t last,
                                const IndexRange* ranges, int count);

// Adds the pressure and viscosity accelerations of particles [first, last).
void forces_cell_simd(const ForceKernelArgs<float>& a, std::size_t first, std::size_t last,
                      const IndexRange* ranges, int count);
void forces_cell_simd(const ForceKernelArgs<double>& a, std::size_t first, std::size_t last,
                      const IndexRange* ranges, int count);

// Lanes of a float batch in the copy the passes now run (simd::active()),
// asked of that copy: equals simd::float_lanes(simd::active()) on x86-64.
int grid_pass_float_lanes();

}  // namespace swirl::sph
