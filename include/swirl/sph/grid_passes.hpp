// The two SPH passes over a SortedCellGrid, computed on the fly (no lists):
//
//   grid_density(): ρ_i = Σ_{j: r_ij < h} m_j W_poly6(r_ij)  (self included,
//                   eq. 2.3) and p_i from the equation of state (eq. 2.9);
//   grid_forces():  a_i += f_i / ρ_i with the pressure (eq. 2.8) and viscosity
//                   (eq. 2.10) forces of sph_fluid.hpp.
//
// Both walk the particles in memory (= cell) order; the particles of one cell
// share its 9 neighbour ranges, which are scanned whole: every candidate j is
// distance-tested and masked with spatial::within(), so the pairs are exactly
// the hash's. Two implementations of each pass, selected by `Simd`:
//  - Simd = true: explicit SIMD with xsimd (the widest batch the build's
//    target has: 16 floats with AVX-512, 4 with the portable x86-64 SSE2), a
//    batch of candidates per iteration, lanes past the range masked;
//  - Simd = false: the scalar twin (the same formulas one pair at a time), the
//    reference the SIMD path is tested against and the "without vectorisation"
//    of the benchmark.
// Each particle's sums are gathered into its own entries in a fixed order that
// depends only on positions and memory order: bit-identical for any thread
// count (not between Simd and scalar: the summation order differs).
// Units as in sph_fluid.hpp (SI).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <xsimd/xsimd.hpp>

#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/distance.hpp"
#include "swirl/sph/kernels.hpp"

// GCC 12 reports the deliberately undefined pass-through operand of the
// AVX-512 intrinsics xsimd calls (_mm512_undefined_ps) as maybe-uninitialized
// (and uninitialized) where they are inlined into this file: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace swirl::sph {

// The constants of the two passes, from the parameters of sph_fluid.hpp.
template <class Real>
struct GridPassConstants {
  Real h = 1, h2 = 1;
  Real rest_density = 1000, c2 = 100, pressure_floor = 0;  // p = max(floor, c² (ρ − ρ0))
  Real mu = 0, half = Real(0.5);                          // viscosity; ½ for eq. 2.8, 1 consistent
};

// Per-particle values the density pass leaves for the force pass (sorted
// order): V_i = m_i / ρ_i and p_i V_i, so that a pair costs no division but 1/r.
template <class Real>
struct GridScratch {
  AlignedVector<Real> volume, pressure_volume;
  std::size_t bytes() const { return (volume.capacity() + pressure_volume.capacity()) * sizeof(Real); }
};

namespace detail {

// Runs body(i, ranges, count) for every particle of [b, e), grouped by cell so
// that a cell's ranges are found once.
template <class Real, class Body>
void for_each_in_cells(const spatial::SortedCellGrid<Real>& grid, std::size_t b, std::size_t e, Body&& body) {
  spatial::NeighbourRanges ranges{};
  std::size_t i = b;
  while (i < e) {
    const std::size_t cell_end = std::min<std::size_t>(e, grid.cell_end(static_cast<std::uint32_t>(i)));
    const int count = grid.neighbour_ranges(grid.keys()[i], ranges);
    for (; i < cell_end; ++i) body(i, ranges, count);
  }
}

template <class Real>
struct Lanes {
  using Batch = xsimd::batch<Real>;
  static constexpr std::size_t W = Batch::size;
  // iota[k] = k: the lane numbers, for masking lanes past a range's end.
  static Batch iota() {
    alignas(64) std::array<Real, W> v{};
    for (std::size_t k = 0; k < W; ++k) v[k] = Real(k);
    return Batch::load_aligned(v.data());
  }
};

// 1/√x for x > 0. For float: the hardware estimate (rsqrt14 with AVX-512, 12
// bits below) and one Newton step, relative error ≤ ~2⁻²² — below the float
// rounding of the sums it enters, and 2–3× cheaper than a square root and a
// division; elsewhere exact to rounding.
template <class Batch>
inline Batch inverse_sqrt(const Batch& x) {
  using T = typename Batch::value_type;
  if constexpr (std::is_same_v<T, float>) {
    Batch y;
    if constexpr (Batch::size == 16) {
#if defined(__AVX512F__)
      y = Batch(_mm512_rsqrt14_ps(x));
#else
      return Batch(T(1)) / xsimd::sqrt(x);
#endif
    } else if constexpr (Batch::size == 8) {
#if defined(__AVX__)
      y = Batch(_mm256_rsqrt_ps(x));
#else
      return Batch(T(1)) / xsimd::sqrt(x);
#endif
    } else if constexpr (Batch::size == 4) {
#if defined(__SSE__)
      y = Batch(_mm_rsqrt_ps(x));
#else
      return Batch(T(1)) / xsimd::sqrt(x);
#endif
    } else {
      return Batch(T(1)) / xsimd::sqrt(x);
    }
    return y * (Batch(T(1.5)) - Batch(T(0.5)) * x * y * y);
  } else {
    return Batch(T(1)) / xsimd::sqrt(x);
  }
}

}  // namespace detail

// Density and pressure of every particle; returns the neighbour pairs found
// (self excluded), for the mean neighbour count.
template <class Real, bool Simd>
std::uint64_t grid_density(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                           const GridPassConstants<Real>& k, std::size_t block_size, GridScratch<Real>& scratch) {
  const std::size_t n = p.size();
  scratch.volume.resize(n);
  scratch.pressure_volume.resize(n);
  Real *volume = scratch.volume.data(), *pressure_volume = scratch.pressure_volume.data();
  const Poly6<Real> w(k.h);
  const Real h2 = w.h2;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  Real *rho = p.density.data(), *pr = p.pressure.data();
  return parallel::reduce_blocks(
      "sph_grid_density", n, block_size, std::uint64_t{0},
      [&](std::size_t b, std::size_t e) {
        std::uint64_t pairs = 0;
        detail::for_each_in_cells(grid, b, e, [&](std::size_t i, const auto& ranges, int count) {
          Real sum = 0;
          std::uint64_t found = 0;
          if constexpr (Simd) {
            using L = detail::Lanes<Real>;
            using B = typename L::Batch;
            const B iota = L::iota(), xi(x[i]), yi(y[i]), zi(z[i]), hh(h2), zero(Real(0)), one(Real(1));
            B acc(Real(0)), hits(Real(0));
            Real tail = 0;
            for (int r = 0; r < count; ++r) {
              std::size_t j = ranges[static_cast<std::size_t>(r)].begin;
              const std::size_t end = ranges[static_cast<std::size_t>(r)].end;
              for (; j < end && j + L::W <= n; j += L::W) {
                const B dx = xi - B::load_unaligned(x + j), dy = yi - B::load_unaligned(y + j),
                        dz = zi - B::load_unaligned(z + j);
                const B r2 = dx * dx + dy * dy + dz * dz;
                const auto in = (r2 < hh) & (iota < B(Real(std::min(end - j, L::W))));
                const B d = hh - r2;
                acc += xsimd::select(in, B::load_unaligned(m + j) * d * d * d, zero);
                hits += xsimd::select(in, one, zero);
              }
              for (; j < end; ++j) {  // the last particles of the array: no full batch to load
                const Real r2 = spatial::distance2(x[i], y[i], z[i], x[j], y[j], z[j]);
                if (spatial::within(r2, h2)) {
                  const Real d = h2 - r2;
                  tail += m[j] * d * d * d;
                  ++found;
                }
              }
            }
            sum = xsimd::hadd(acc) + tail;
            found += static_cast<std::uint64_t>(xsimd::hadd(hits));
          } else {
            for (int r = 0; r < count; ++r)
              for (std::size_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j) {
                const Real r2 = spatial::distance2(x[i], y[i], z[i], x[j], y[j], z[j]);
                if (spatial::within(r2, h2)) {
                  const Real d = h2 - r2;
                  sum += m[j] * d * d * d;
                  ++found;
                }
              }
          }
          const Real density = w.norm * sum;
          rho[i] = density;
          pr[i] = std::max(k.pressure_floor, k.c2 * (density - k.rest_density));
          volume[i] = m[i] / density;
          pressure_volume[i] = pr[i] * volume[i];
          pairs += found - 1;  // the particle itself is in its own cell's range
        });
        return pairs;
      },
      [](std::uint64_t a, std::uint64_t b) { return a + b; });
}

// Adds the pressure and viscosity accelerations (densities, pressures and the
// scratch from grid_density()). Per pair, with V_j = m_j / ρ_j:
//   pressure  (p_i V_j + p_j V_j) · ½ · (−∇W_spiky factor) · r⃗      (eq. 2.8)
//   viscosity μ V_j ∇²W_viscosity · (v_j − v_i)                     (eq. 2.10)
// the kernel constants applied once per particle.
template <class Real, bool Simd>
void grid_forces(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p, const GridPassConstants<Real>& k,
                 std::size_t block_size, const GridScratch<Real>& scratch) {
  const std::size_t n = p.size();
  const Spiky<Real> spiky(k.h);
  const Viscosity<Real> visc(k.h);
  const Real h = k.h, h2 = k.h * k.h;
  // grad_norm < 0: the pressure term pushes i away from j.
  const Real pressure_norm = -spiky.grad_norm * k.half, visc_norm = k.mu * visc.laplacian_norm;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  const Real *V = scratch.volume.data(), *PV = scratch.pressure_volume.data(), *pr = p.pressure.data();
  const Real* rho = p.density.data();
  Real *ax = p.acceleration.x.data(), *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
  // Pressure sums (fp) and viscosity sums (fv) of particle i.
  struct Sums {
    Real px = 0, py = 0, pz = 0, vx = 0, vy = 0, vz = 0;
  };
  // One pair, scalar (the twin, and the SIMD path's array tail).
  auto pair = [&](std::size_t i, std::size_t j, Sums& s) {
    const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
    const Real r2 = dx * dx + dy * dy + dz * dz;
    if (!spatial::within(r2, h2)) return;
    const Real r = std::sqrt(r2), q = std::max(h - r, Real(0));
    const Real g = r > Real(0) ? q * q / r : Real(0);
    const Real fp = (pr[i] * V[j] + PV[j]) * g;
    const Real fv = V[j] * q;
    s.px += fp * dx;
    s.py += fp * dy;
    s.pz += fp * dz;
    s.vx += fv * (vx[j] - vx[i]);
    s.vy += fv * (vy[j] - vy[i]);
    s.vz += fv * (vz[j] - vz[i]);
  };
  parallel::for_blocks("sph_grid_forces", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    detail::for_each_in_cells(grid, b, e, [&](std::size_t i, const auto& ranges, int count) {
      Sums s;
      if constexpr (Simd) {
        using L = detail::Lanes<Real>;
        using B = typename L::Batch;
        const B iota = L::iota(), xi(x[i]), yi(y[i]), zi(z[i]), vxi(vx[i]), vyi(vy[i]), vzi(vz[i]), pri(pr[i]);
        const B hh(h2), hb(h), zero(Real(0)), one(Real(1));
        B spx(Real(0)), spy(Real(0)), spz(Real(0)), svx(Real(0)), svy(Real(0)), svz(Real(0));
        for (int r = 0; r < count; ++r) {
          std::size_t j = ranges[static_cast<std::size_t>(r)].begin;
          const std::size_t end = ranges[static_cast<std::size_t>(r)].end;
          for (; j < end && j + L::W <= n; j += L::W) {
            const B dx = xi - B::load_unaligned(x + j), dy = yi - B::load_unaligned(y + j),
                    dz = zi - B::load_unaligned(z + j);
            const B r2 = dx * dx + dy * dy + dz * dz;
            const auto in = (r2 < hh) & (iota < B(Real(std::min(end - j, L::W))));
            const auto apart = r2 > zero;
            const B inv_r = detail::inverse_sqrt(xsimd::select(apart, r2, one));
            const B q = xsimd::max(hb - r2 * inv_r, zero);
            const B Vj = B::load_unaligned(V + j);
            const B g = xsimd::select(apart & in, q * q * inv_r, zero);
            const B fp = (pri * Vj + B::load_unaligned(PV + j)) * g;
            const B fv = xsimd::select(in, Vj * q, zero);
            spx += fp * dx;
            spy += fp * dy;
            spz += fp * dz;
            svx += fv * (B::load_unaligned(vx + j) - vxi);
            svy += fv * (B::load_unaligned(vy + j) - vyi);
            svz += fv * (B::load_unaligned(vz + j) - vzi);
          }
          for (; j < end; ++j) pair(i, j, s);
        }
        s.px += xsimd::hadd(spx);
        s.py += xsimd::hadd(spy);
        s.pz += xsimd::hadd(spz);
        s.vx += xsimd::hadd(svx);
        s.vy += xsimd::hadd(svy);
        s.vz += xsimd::hadd(svz);
      } else {
        for (int r = 0; r < count; ++r)
          for (std::size_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j)
            pair(i, j, s);
      }
      const Real inv_rho = Real(1) / rho[i];
      ax[i] += (pressure_norm * s.px + visc_norm * s.vx) * inv_rho;
      ay[i] += (pressure_norm * s.py + visc_norm * s.vy) * inv_rho;
      az[i] += (pressure_norm * s.pz + visc_norm * s.vz) * inv_rho;
    });
  });
}

}  // namespace swirl::sph

#pragma GCC diagnostic pop
