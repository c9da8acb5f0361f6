// The explicit-SIMD cell bodies of the SPH grid passes (sph/grid_pass_kernels.hpp).
// Compiled once per instruction set by CMake's swirl_simd_sources(): here
// xsimd::batch<Real> is that set's width and everything lives in
// namespace SWIRL_SIMD_NS, so that no inline function of one copy can stand in
// for another's (tools/check_simd_objects.sh). Kept to xsimd and plain structs.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include <xsimd/xsimd.hpp>

#include "swirl/core/simd_rsqrt.hpp"
#include "swirl/sph/grid_pass_kernels.hpp"
#include "swirl/sph/laws.hpp"

// GCC 12 reports the deliberately undefined pass-through operand of the
// AVX-512 intrinsics xsimd calls (_mm512_undefined_ps) as maybe-uninitialized
// (and uninitialized) where they are inlined into this file: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace swirl::sph::SWIRL_SIMD_NS {

namespace {

template <class Real>
using Batch = xsimd::batch<Real>;

template <class Real>
constexpr std::size_t kLanes = Batch<Real>::size;

// iota[k] = k: the lane numbers, for masking lanes past a range's end.
template <class Real>
Batch<Real> lane_numbers() {
  alignas(64) Real v[kLanes<Real>];
  for (std::size_t k = 0; k < kLanes<Real>; ++k) v[k] = Real(k);
  return Batch<Real>::load_aligned(v);
}

// Lanes of the batch that lie inside a range with `left` candidates from j on.
template <class Real>
Real live_lanes(std::size_t left) {
  return Real(left < kLanes<Real> ? left : kLanes<Real>);
}

// 1/√x for x > 0. For float: the hardware estimate (rsqrt14 with AVX-512, 12
// bits below) and one Newton step, relative error ≤ ~2⁻²² — below the float
// rounding of the sums it enters, and 2–3× cheaper than a square root and a
// division; elsewhere exact to rounding.
template <class B>
B inverse_sqrt(const B& x) {
  using T = typename B::value_type;
  if constexpr (std::is_same_v<T, float> && simd::SWIRL_SIMD_NS::kHasRsqrtEstimate<float>) {
    const B y = simd::SWIRL_SIMD_NS::rsqrt_estimate(x);
    return y * (B(T(1.5)) - B(T(0.5)) * x * y * y);
  } else {
    return B(T(1)) / xsimd::sqrt(x);
  }
}

template <class Real>
std::uint64_t density_cell(const DensityKernelArgs<Real>& a, std::size_t first, std::size_t last,
                           const IndexRange* ranges, int count) {
  using B = Batch<Real>;
  constexpr std::size_t W = kLanes<Real>;
  const Real *x = a.x, *y = a.y, *z = a.z, *m = a.mass;
  const std::size_t n = a.n;
  // A local copy: the stores to the particle arrays below cannot alias it, so
  // h² stays in a register across the ranges (read through a reference it was
  // reloaded per range: 3 % more instructions per cell in the AVX2 copy, callgrind).
  const SphLaws<Real> laws = a.laws;
  const Real h2 = laws.h2;
  const B iota = lane_numbers<Real>(), zero(Real(0)), one(Real(1));
  std::uint64_t pairs = 0;
  for (std::size_t i = first; i < last; ++i) {
    const B xi(x[i]), yi(y[i]), zi(z[i]);
    B acc(Real(0)), hits(Real(0));
    Real tail = 0;
    std::uint64_t found = 0;
    for (int r = 0; r < count; ++r) {
      std::size_t j = ranges[r].begin;
      const std::size_t end = ranges[r].end;
      for (; j < end && j + W <= n; j += W) {
        const B dx = xi - B::load_unaligned(x + j), dy = yi - B::load_unaligned(y + j), dz = zi - B::load_unaligned(z + j);
        const B r2 = dx * dx + dy * dy + dz * dz;
        // h² − r² > 0 exactly when r² < h² (a difference of finite floats is 0 only if they are equal).
        const B d = laws.gap2(r2);
        const auto in = (d > zero) & (iota < B(live_lanes<Real>(end - j)));
        acc += xsimd::select(in, laws.density.term(B::load_unaligned(m + j), d), zero);
        hits += xsimd::select(in, one, zero);
      }
      for (; j < end; ++j) {  // the last particles of the array: no full batch to load
        const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
        const Real r2 = dx * dx + dy * dy + dz * dz;
        if (r2 < h2) {
          tail += laws.density.term(m[j], laws.gap2(r2));
          ++found;
        }
      }
    }
    const Real sum = xsimd::hadd(acc) + tail;
    found += static_cast<std::uint64_t>(xsimd::hadd(hits));
    const Real density = laws.density.density(sum);
    a.density[i] = density;
    a.pressure[i] = laws.eos.pressure(density);
    a.volume[i] = m[i] / density;
    a.pressure_volume[i] = a.pressure[i] * a.volume[i];
    pairs += found - 1;  // the particle itself is in its own cell's range
  }
  return pairs;
}

template <class Real>
void forces_cell(const ForceKernelArgs<Real>& a, std::size_t first, std::size_t last, const IndexRange* ranges,
                 int count) {
  using B = Batch<Real>;
  constexpr std::size_t W = kLanes<Real>;
  const Real *x = a.x, *y = a.y, *z = a.z, *vx = a.vx, *vy = a.vy, *vz = a.vz;
  const Real *V = a.volume, *PV = a.pressure_volume, *pr = a.pressure;
  const std::size_t n = a.n;
  // By reference here: nothing is reloaded per pair, and a local copy measured
  // more instructions per cell in this longer loop (AVX2 copy, callgrind).
  const SphLaws<Real>& laws = a.laws;
  const Real h2 = laws.h2;
  const B iota = lane_numbers<Real>(), hh(h2), zero(Real(0)), one(Real(1));
  for (std::size_t i = first; i < last; ++i) {
    const B xi(x[i]), yi(y[i]), zi(z[i]), vxi(vx[i]), vyi(vy[i]), vzi(vz[i]), pri(pr[i]);
    B spx(Real(0)), spy(Real(0)), spz(Real(0)), svx(Real(0)), svy(Real(0)), svz(Real(0));
    Real px = 0, py = 0, pz = 0, qx = 0, qy = 0, qz = 0;  // the scalar tail's pressure, viscosity sums
    for (int r = 0; r < count; ++r) {
      std::size_t j = ranges[r].begin;
      const std::size_t end = ranges[r].end;
      for (; j < end && j + W <= n; j += W) {
        const B dx = xi - B::load_unaligned(x + j), dy = yi - B::load_unaligned(y + j), dz = zi - B::load_unaligned(z + j);
        const B r2 = dx * dx + dy * dy + dz * dz;
        const auto in = (r2 < hh) & (iota < B(live_lanes<Real>(end - j)));
        const auto apart = r2 > zero;
        const B inv_r = inverse_sqrt(xsimd::select(apart, r2, one));
        const B q = laws.gap(r2 * inv_r);
        const B Vj = B::load_unaligned(V + j);
        // Lanes out of range, and r = 0 for the pressure (no direction), masked after the laws.
        const B fp = xsimd::select(apart & in, laws.pressure.term(pri, Vj, B::load_unaligned(PV + j), q, inv_r), zero);
        const B fv = xsimd::select(in, laws.viscosity.term(Vj, q), zero);
        spx += fp * dx;
        spy += fp * dy;
        spz += fp * dz;
        svx += fv * (B::load_unaligned(vx + j) - vxi);
        svy += fv * (B::load_unaligned(vy + j) - vyi);
        svz += fv * (B::load_unaligned(vz + j) - vzi);
      }
      for (; j < end; ++j) {  // the last particles of the array, one pair at a time (as the scalar twin)
        const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
        const Real r2 = dx * dx + dy * dy + dz * dz;
        if (!(r2 < h2)) continue;
        const Real rr = std::sqrt(r2), inv_r = rr > Real(0) ? Real(1) / rr : Real(0);  // 1/r = 0: no pressure at r = 0
        const Real q = laws.gap(rr);
        const Real fp = laws.pressure.term(pr[i], V[j], PV[j], q, inv_r);
        const Real fv = laws.viscosity.term(V[j], q);
        px += fp * dx;
        py += fp * dy;
        pz += fp * dz;
        qx += fv * (vx[j] - vx[i]);
        qy += fv * (vy[j] - vy[i]);
        qz += fv * (vz[j] - vz[i]);
      }
    }
    px += xsimd::hadd(spx);
    py += xsimd::hadd(spy);
    pz += xsimd::hadd(spz);
    qx += xsimd::hadd(svx);
    qy += xsimd::hadd(svy);
    qz += xsimd::hadd(svz);
    if (laws.corrected) {
      Real L[6];
      for (int k = 0; k < 6; ++k) L[k] = a.correction[k][i];
      GradientCorrection<Real>::apply(L, px, py, pz);
    }
    const Real inv_rho = Real(1) / a.density[i];
    a.ax[i] += laws.acceleration(px, qx, inv_rho);
    a.ay[i] += laws.acceleration(py, qy, inv_rho);
    a.az[i] += laws.acceleration(pz, qz, inv_rho);
  }
}

}  // namespace

std::uint64_t density_cell_simd(const DensityKernelArgs<float>& a, std::size_t first, std::size_t last,
                                const IndexRange* ranges, int count) {
  return density_cell(a, first, last, ranges, count);
}
std::uint64_t density_cell_simd(const DensityKernelArgs<double>& a, std::size_t first, std::size_t last,
                                const IndexRange* ranges, int count) {
  return density_cell(a, first, last, ranges, count);
}
void forces_cell_simd(const ForceKernelArgs<float>& a, std::size_t first, std::size_t last,
                      const IndexRange* ranges, int count) {
  forces_cell(a, first, last, ranges, count);
}
void forces_cell_simd(const ForceKernelArgs<double>& a, std::size_t first, std::size_t last,
                      const IndexRange* ranges, int count) {
  forces_cell(a, first, last, ranges, count);
}
int grid_pass_float_lanes() { return static_cast<int>(kLanes<float>); }

}  // namespace swirl::sph::SWIRL_SIMD_NS

#pragma GCC diagnostic pop
