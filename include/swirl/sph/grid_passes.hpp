// The two SPH passes over a SortedCellGrid, computed on the fly (no lists):
//
//   grid_density(): ρ_i = Σ_{j: r_ij < h} m_j W_poly6(r_ij)  (self included,
//                   eq. 2.3) and p_i from the equation of state (eq. 2.9);
//   grid_forces():  a_i += f_i / ρ_i with the pressure (eq. 2.8) and viscosity
//                   (eq. 2.10) forces of sph_fluid.hpp.
// The laws themselves are sph/laws.hpp's evaluators (SphLaws): these loops
// only find the pairs, sum the evaluators' terms and store the results.
//
// Both walk the particles in memory (= cell) order; the particles of one cell
// share its neighbour ranges (spatial::NeighbourRanges), which are scanned
// whole: every candidate j is distance-tested and masked with
// spatial::within(), so the pairs are exactly the hash's (to the rounding of
// r² where the AVX2/AVX-512 copies fuse it into FMAs: a pair within one ulp of
// h² may fall either way). Two implementations of each pass, selected at run
// time by a KernelPath (core/kernel_path.hpp; the scene key sph.grid.simd):
//  - KernelPath::Simd: explicit SIMD with xsimd, a batch of candidates per
//    iteration, lanes past the range masked. The cell bodies are compiled once
//    per instruction set (src/sph/grid_passes_simd.cpp, sph/grid_pass_kernels.hpp)
//    and the width is chosen at run time, not by the build's flags: the widest
//    the CPU runs (16 floats with AVX-512, 8 with AVX2 + FMA, 4 with SSE2), or
//    the one SWIRL_SIMD names (core/simd_dispatch.hpp);
//  - KernelPath::Scalar: the scalar twin (the same evaluators one pair at a
//    time), the reference the SIMD path is tested against and the "without vectorisation"
//    of the benchmark.
// Each particle's sums are gathered into its own entries in a fixed order that
// depends only on positions and memory order: bit-identical for any thread
// count within one instruction set (not between instruction sets, nor between
// Simd and scalar: the summation order differs).
// Units as in sph_fluid.hpp (SI).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "swirl/core/index_range.hpp"
#include "swirl/core/kernel_path.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/distance.hpp"
#include "swirl/sph/grid_pass_kernels.hpp"
#include "swirl/sph/laws.hpp"

namespace swirl::sph {

// Per-particle values the density pass leaves for the force pass (sorted
// order): V_i = m_i / ρ_i and p_i V_i, so that a pair costs no division but 1/r.
// With the gradient correction on, grid_gradient_correction() leaves L_i
// (xx, xy, xz, yy, yz, zz; sph/laws.hpp) for the force pass.
template <class Real>
struct GridScratch {
  AlignedVector<Real> volume, pressure_volume;
  std::array<AlignedVector<Real>, 6> correction;
  std::size_t bytes() const {
    std::size_t reals = volume.capacity() + pressure_volume.capacity();
    for (const auto& c : correction) reals += c.capacity();
    return reals * sizeof(Real);
  }
};

namespace detail {

// Runs body(first, last, ranges, count) for every cell's particles
// [first, last) within [b, e), with the cell's neighbour ranges.
template <class Real, class Body>
void for_each_cell(const spatial::SortedCellGrid<Real>& grid, std::size_t b, std::size_t e, Body&& body) {
  spatial::NeighbourRanges ranges{};
  std::size_t i = b;
  while (i < e) {
    const std::size_t cell_end = std::min<std::size_t>(e, grid.cell_end(static_cast<std::uint32_t>(i)));
    const int count = grid.neighbour_ranges(grid.keys()[i], ranges);
    body(i, cell_end, ranges, count);
    i = cell_end;
  }
}

// Runs body(i, ranges, count) for every particle of [b, e), grouped by cell so
// that a cell's ranges are found once.
template <class Real, class Body>
void for_each_in_cells(const spatial::SortedCellGrid<Real>& grid, std::size_t b, std::size_t e, Body&& body) {
  for_each_cell(grid, b, e, [&](std::size_t first, std::size_t last, const spatial::NeighbourRanges& ranges, int count) {
    for (std::size_t i = first; i < last; ++i) body(i, ranges, count);
  });
}

// Every particle of p, as an IndexRange.
template <class Real>
IndexRange all_of(const ParticleSet<Real>& p) {
  return {0, static_cast<std::uint32_t>(p.size())};
}

inline void check_range(IndexRange only, std::size_t n) {
  if (only.begin > only.end || only.end > n)
    throw std::invalid_argument("SPH grid pass: the particles to compute are not a range of the particles");
}

// The particles in a cell's neighbour ranges: each of the cell's particles'
// neighbour candidates (grid_candidates()).
template <class Ranges>
std::uint64_t candidates_in(const Ranges& ranges, int count) {
  std::uint64_t candidates = 0;
  for (int r = 0; r < count; ++r) candidates += ranges[std::size_t(r)].end - ranges[std::size_t(r)].begin;
  return candidates;
}

}  // namespace detail

// The neighbour candidates of each particle of `only`: how many particles the
// cells its passes scan hold (itself included), into out[i − only.begin]. The
// passes' work per particle as an integer, for balancing the ranks of a
// distributed run (force/solver.hpp, add_rank_costs).
template <class Real>
void grid_candidates(const spatial::SortedCellGrid<Real>& grid, IndexRange only, std::size_t block_size,
                     std::span<std::uint64_t> out) {
  if (only.begin > only.end || out.size() != std::size_t(only.end - only.begin))
    throw std::invalid_argument("SPH grid candidates: the output is not one entry per particle of the range");
  const std::size_t from = only.begin;
  parallel::for_blocks("sph_grid_candidates", out.size(), block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    detail::for_each_cell(grid, from + b, from + e,
                          [&](std::size_t first, std::size_t last, const spatial::NeighbourRanges& ranges, int count) {
                            const std::uint64_t candidates = detail::candidates_in(ranges, count);
                            for (std::size_t i = first; i < last; ++i) out[i - from] = candidates;
                          });
  });
}

// Density and pressure of every particle; returns the neighbour pairs found
// (self excluded), for the mean neighbour count.
//
// `only` (the overloads with it): computes particles [only.begin, only.end)
// alone, reading the others as neighbours (a rank's own particles among its
// ghosts, dist/halo.hpp); the scratch still has one entry per particle. Each
// particle's result is the same bits as in a pass over all.
//
// candidates (optional: empty, or one entry per particle of `only`): each
// particle's neighbour candidates as grid_candidates() counts them, found on
// the way (the ranks' cost per particle without a pass of its own).
template <class Real>
std::uint64_t grid_density(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p, const SphLaws<Real>& laws,
                           std::size_t block_size, GridScratch<Real>& scratch, KernelPath path, IndexRange only,
                           std::span<std::uint64_t> candidates = {}) {
  const std::size_t n = p.size();
  detail::check_range(only, n);
  const std::size_t from = only.begin, todo = only.end - only.begin;
  if (!candidates.empty() && candidates.size() != todo)
    throw std::invalid_argument("SPH grid density: the candidates are not one entry per particle of the range");
  const auto count_candidates = [&](std::size_t first, std::size_t last, const auto& ranges, int count) {
    if (candidates.empty()) return;
    const std::uint64_t found = detail::candidates_in(ranges, count);
    for (std::size_t i = first; i < last; ++i) candidates[i - from] = found;
  };
  scratch.volume.resize(n);
  scratch.pressure_volume.resize(n);
  Real *volume = scratch.volume.data(), *pressure_volume = scratch.pressure_volume.data();
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  Real *rho = p.density.data(), *pr = p.pressure.data();
  const auto sum_blocks = [](std::uint64_t a, std::uint64_t b) { return a + b; };
  if (path == KernelPath::Simd) {
    simd::active();  // a bad SWIRL_SIMD throws here, not inside the parallel region
    DensityKernelArgs<Real> a;
    a.x = x, a.y = y, a.z = z, a.mass = m, a.density = rho, a.pressure = pr;
    a.volume = volume, a.pressure_volume = pressure_volume, a.n = n;
    a.laws = laws;
    return parallel::reduce_blocks_pinned(
        "sph_grid_density", todo, block_size, std::uint64_t{0},
        [&](std::size_t b, std::size_t e) {
          std::uint64_t pairs = 0;
          detail::for_each_cell(grid, from + b, from + e, [&](std::size_t first, std::size_t last, const auto& ranges, int count) {
            pairs += density_cell_simd(a, first, last, ranges.data(), count);
            count_candidates(first, last, ranges, count);
          });
          return pairs;
        },
        sum_blocks);
  } else {
    return parallel::reduce_blocks_pinned(
        "sph_grid_density", todo, block_size, std::uint64_t{0},
        [&](std::size_t b, std::size_t e) {
          // A copy in the block: the stores below cannot alias it, so its
          // constants stay in registers and the pair loop has no load of them
          // to keep conditional (read through the reference, the pass ran 2.5×
          // slower natively: g++ no longer vectorised the pair loop).
          const SphLaws<Real> law = laws;
          std::uint64_t pairs = 0;
          detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
            count_candidates(i, i + 1, ranges, count);
            Real sum = 0;
            std::uint64_t found = 0;
            for (int r = 0; r < count; ++r)
              for (std::size_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j) {
                const Real r2 = spatial::distance2(x[i], y[i], z[i], x[j], y[j], z[j]);
                if (spatial::within(r2, law.h2)) {
                  sum += law.density.term(m[j], law.gap2(r2));
                  ++found;
                }
              }
            const Real density = law.density.density(sum);
            rho[i] = density;
            pr[i] = law.eos.pressure(density);
            volume[i] = m[i] / density;
            pressure_volume[i] = pr[i] * volume[i];
            pairs += found - 1;  // the particle itself is in its own cell's range
          });
          return pairs;
        },
        sum_blocks);
  }
}

template <class Real>
std::uint64_t grid_density(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p, const SphLaws<Real>& laws,
                           std::size_t block_size, GridScratch<Real>& scratch, KernelPath path) {
  return grid_density(grid, p, laws, block_size, scratch, path, detail::all_of(p));
}

// The gradient correction L_i = M_i⁻¹ of every particle (laws.correction,
// sph/laws.hpp) into scratch.correction, from the volumes grid_density() left.
// One scalar pass over the same pairs; run only when laws.corrected.
template <class Real>
void grid_gradient_correction(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& p,
                              const SphLaws<Real>& laws, std::size_t block_size, GridScratch<Real>& scratch,
                              IndexRange only) {
  const std::size_t n = p.size();
  detail::check_range(only, n);
  const std::size_t from = only.begin;
  for (auto& c : scratch.correction) c.resize(n);
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
  const Real* V = scratch.volume.data();
  const std::size_t todo = only.end - only.begin;
  parallel::for_blocks_pinned("sph_grid_correction", todo, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    const SphLaws<Real> law = laws;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      Real m6[6] = {};
      for (int r = 0; r < count; ++r)
        for (std::size_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j) {
          const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
          const Real r2 = dx * dx + dy * dy + dz * dz;
          if (!spatial::within(r2, law.h2)) continue;
          const Real rr = std::sqrt(r2), inv_r = rr > Real(0) ? Real(1) / rr : Real(0);
          add_correction_term(law.correction.term(V[j], law.gap(rr), inv_r), dx, dy, dz, m6);
        }
      Real L[6];
      law.correction.inverse(m6, L);
      for (int k = 0; k < 6; ++k) scratch.correction[static_cast<std::size_t>(k)][i] = L[k];
    });
  });
}

template <class Real>
void grid_gradient_correction(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& p,
                              const SphLaws<Real>& laws, std::size_t block_size, GridScratch<Real>& scratch) {
  grid_gradient_correction(grid, p, laws, block_size, scratch, detail::all_of(p));
}

// Adds the pressure and viscosity accelerations (densities, pressures and the
// scratch from grid_density(); with laws.corrected also grid_gradient_correction()'s): per pair PressureLaw::term · r⃗ and
// ViscosityLaw::term · (v_j − v_i) summed, SphLaws::acceleration() once per
// particle.
template <class Real>
void grid_forces(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p, const SphLaws<Real>& laws,
                 std::size_t block_size, const GridScratch<Real>& scratch, KernelPath path, IndexRange only) {
  const std::size_t n = p.size();
  detail::check_range(only, n);
  const std::size_t from = only.begin, todo = only.end - only.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  const Real *V = scratch.volume.data(), *PV = scratch.pressure_volume.data(), *pr = p.pressure.data();
  const Real* rho = p.density.data();
  Real *ax = p.acceleration.x.data(), *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
  if (path == KernelPath::Simd) {
    simd::active();  // a bad SWIRL_SIMD throws here, not inside the parallel region
    ForceKernelArgs<Real> a;
    a.x = x, a.y = y, a.z = z, a.vx = vx, a.vy = vy, a.vz = vz;
    a.volume = V, a.pressure_volume = PV, a.pressure = pr, a.density = rho;
    a.ax = ax, a.ay = ay, a.az = az, a.n = n;
    a.laws = laws;
    if (laws.corrected)
      for (int k = 0; k < 6; ++k) a.correction[k] = scratch.correction[static_cast<std::size_t>(k)].data();
    parallel::for_blocks_pinned("sph_grid_forces", todo, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      detail::for_each_cell(grid, from + b, from + e, [&](std::size_t first, std::size_t last, const auto& ranges, int count) {
        forces_cell_simd(a, first, last, ranges.data(), count);
      });
    });
    return;
  }
  // The scalar twin: pressure sums (px..) and viscosity sums (vx..) of particle i.
  struct Sums {
    Real px = 0, py = 0, pz = 0, vx = 0, vy = 0, vz = 0;
  };
  parallel::for_blocks_pinned("sph_grid_forces", todo, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    const SphLaws<Real> law = laws;  // a copy in the block, as in grid_density (no reloads)
    auto pair = [&](std::size_t i, std::size_t j, Sums& s) {
      const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const Real r2 = dx * dx + dy * dy + dz * dz;
      if (!spatial::within(r2, law.h2)) return;
      // 1/r = 0 at r = 0 takes the pair (i itself, or a coincident j) out of the pressure sum.
      const Real r = std::sqrt(r2), inv_r = r > Real(0) ? Real(1) / r : Real(0), q = law.gap(r);
      const Real fp = law.pressure.term(pr[i], V[j], PV[j], q, inv_r);
      const Real fv = law.viscosity.term(V[j], q);
      s.px += fp * dx;
      s.py += fp * dy;
      s.pz += fp * dz;
      s.vx += fv * (vx[j] - vx[i]);
      s.vy += fv * (vy[j] - vy[i]);
      s.vz += fv * (vz[j] - vz[i]);
    };
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      Sums s;
      for (int r = 0; r < count; ++r)
        for (std::size_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j)
          pair(i, j, s);
      if (law.corrected) {
        Real L[6];
        for (int k = 0; k < 6; ++k) L[k] = scratch.correction[static_cast<std::size_t>(k)][i];
        GradientCorrection<Real>::apply(L, s.px, s.py, s.pz);
      }
      const Real inv_rho = Real(1) / rho[i];
      ax[i] += law.acceleration(s.px, s.vx, inv_rho);
      ay[i] += law.acceleration(s.py, s.vy, inv_rho);
      az[i] += law.acceleration(s.pz, s.vz, inv_rho);
    });
  });
}

template <class Real>
void grid_forces(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p, const SphLaws<Real>& laws,
                 std::size_t block_size, const GridScratch<Real>& scratch, KernelPath path) {
  grid_forces(grid, p, laws, block_size, scratch, path, detail::all_of(p));
}

}  // namespace swirl::sph
