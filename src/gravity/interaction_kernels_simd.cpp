// The SIMD interaction kernels (interaction_kernels.hpp), compiled once per
// instruction set into namespace SWIRL_SIMD_NS (core/simd_dispatch.hpp).
//
// Vectorisation axis: the targets. A batch of W targets (W = 16 floats with
// AVX-512, 8 with AVX2, 4 with SSE2; half as many doubles) is held in
// registers with its four sums; each source is broadcast to all lanes, so a
// source costs no shuffle, no horizontal sum and no gather, and a group of
// 16–64 targets against a list of hundreds of sources runs at full width.
// Sources are taken two at a time into two sets of sums (added at the end),
// so that the adds into the sums do not wait on each other.
//
// The last targets (fewer than W): when the list is long they go sources
// across the lanes instead, one target at a time with horizontal sums at the
// end (W sources per step: no lane idles but in the list's last step); when
// it is short (then a pass over it costs little) as one padded batch
// (padding lanes repeat the last target and are never written back). The
// choice depends on the sizes only. Nothing past n is read or written.
//
// Deterministic: every sum has a fixed order given the inputs and the batch
// width; no state, no threads.
#include <cstddef>
#include <limits>
#include <type_traits>

#include <xsimd/xsimd.hpp>

#include "swirl/core/simd_rsqrt.hpp"
#include "swirl/gravity/interaction_kernels.hpp"
#include "swirl/gravity/pair_law.hpp"

// GCC 12 reports the deliberately undefined pass-through operand of the
// AVX-512 intrinsics xsimd calls (_mm512_undefined_ps) as maybe-uninitialized
// where they are inlined: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace swirl::gravity::SWIRL_SIMD_NS {

namespace {

template <class T>
using Batch = xsimd::batch<T>;

// 1/√x from the hardware's estimate and Newton steps where this copy has
// one: float with SSE and up (rsqrt: 12 bits; rsqrt14 with AVX-512: 14 bits)
// and one step (relative error ≲ 2⁻²², about float rounding); double with
// AVX-512 (rsqrt14) and two steps (~1 ulp). Elsewhere an exact square root
// and division. A Newton step y ← ½ y (3 − x y²) leaves its ½ out when it is
// the last: the kernels get z = 2/√x and fold the powers of 2 into their sums
// at the end (exact), which saves a multiply per pair.
template <class T>
struct Root {
  static constexpr bool estimate = simd::SWIRL_SIMD_NS::kHasRsqrtEstimate<T>;
  static constexpr T scale = estimate ? T(2) : T(1);  // z = scale / √x
};

// z = Root<T>::scale / √x for normal, finite x > 0; with Guard, z = 0 where
// x = 0 (a pair at zero softened distance contributes nothing). Without
// Guard x must be ≥ the smallest normal number: the estimates take
// subnormals for 0.
template <class T, bool Guard>
inline Batch<T> scaled_inverse_sqrt(const Batch<T>& x) {
  using B = Batch<T>;
  B z;
  if constexpr (!Root<T>::estimate) {
    z = B(T(1)) / xsimd::sqrt(x);
  } else {
    B y = simd::SWIRL_SIMD_NS::rsqrt_estimate(x);
    if constexpr (std::is_same_v<T, double>) y = B(T(0.5)) * y * xsimd::fnma(x * y, y, B(T(3)));
    z = y * xsimd::fnma(x * y, y, B(T(3)));
  }
  if constexpr (Guard) z = xsimd::select(x > B(T(0)), z, B(T(0)));
  return z;
}

// Sums per lane, up to the factors applied when they are stored.
template <class T>
struct Sums {
  Batch<T> ax = Batch<T>(T(0)), ay = Batch<T>(T(0)), az = Batch<T>(T(0)), phi = Batch<T>(T(0));
};

// The pair law (gravity/pair_law.hpp) of point masses m at d = source −
// target (per lane; m = 0 in a lane that must not count), with z = c/R (c =
// Root<T>::scale) for 1/R: the sums collect c³ m d / R³ and −c m / R, and
// kPoint*Factor undo c when they are stored (exact: c is a power of 2).
template <class T, bool Guard>
inline void point_law(const Batch<T>& dx, const Batch<T>& dy, const Batch<T>& dz, const Batch<T>& m,
                      const Batch<T>& eps2, Sums<T>& sums) {
  const Batch<T> r2 = xsimd::fma(dx, dx, xsimd::fma(dy, dy, xsimd::fma(dz, dz, eps2)));
  add_point(dx, dy, dz, m, scaled_inverse_sqrt<T, Guard>(r2), sums);
}

template <class T>
constexpr T kPointAccelFactor = T(1) / (Root<T>::scale * Root<T>::scale * Root<T>::scale);
template <class T>
constexpr T kPointPotentialFactor = T(1) / Root<T>::scale;

// Monopole and quadrupole (pair_law.hpp's add_cell) of cells at d = centre of
// mass − target, with 1/R unscaled first (the quadrupole's powers of 1/R do
// not fold into one factor).
template <class T, bool Guard>
inline void quadrupole_law(const Batch<T>& dx, const Batch<T>& dy, const Batch<T>& dz, const Batch<T>& m,
                           const Quadrupole<Batch<T>>& Q, const Batch<T>& eps2, Sums<T>& sums) {
  using B = Batch<T>;
  const B r2 = xsimd::fma(dx, dx, xsimd::fma(dy, dy, xsimd::fma(dz, dz, eps2)));
  B inv = scaled_inverse_sqrt<T, Guard>(r2);
  if constexpr (Root<T>::scale != T(1)) inv = inv * B(T(1) / Root<T>::scale);
  add_cell(dx, dy, dz, m, Q, inv, sums);
}

template <class T>
Batch<T> lane_numbers() {
  constexpr std::size_t W = Batch<T>::size;
  alignas(64) T v[W];
  for (std::size_t k = 0; k < W; ++k) v[k] = T(k);
  return Batch<T>::load_aligned(v);
}

// ---- Targets across the lanes (full batches of W targets) -----------------

// W targets at t[begin, begin + W).
template <class T>
struct TargetBatch {
  Batch<T> x, y, z;
  std::size_t begin;
  explicit TargetBatch(const Targets<T>& t, std::size_t b)
      : x(Batch<T>::load_unaligned(t.x + b)), y(Batch<T>::load_unaligned(t.y + b)),
        z(Batch<T>::load_unaligned(t.z + b)), begin(b) {}
};

// Adds fa · (s0 + s1).a and fp · (s0 + s1).phi to the batch's targets. The
// factors are powers of 2 or their negatives: exact.
template <class T>
void store_batch(const Targets<T>& t, std::size_t i, const Sums<T>& s0, const Sums<T>& s1, T fa, T fp) {
  using B = Batch<T>;
  (B::load_unaligned(t.ax + i) + (s0.ax + s1.ax) * B(fa)).store_unaligned(t.ax + i);
  (B::load_unaligned(t.ay + i) + (s0.ay + s1.ay) * B(fa)).store_unaligned(t.ay + i);
  (B::load_unaligned(t.az + i) + (s0.az + s1.az) * B(fa)).store_unaligned(t.az + i);
  (B::load_unaligned(t.phi + i) + (s0.phi + s1.phi) * B(fp)).store_unaligned(t.phi + i);
}

template <class T, bool Guard>
inline void batch_point(const SourceParticles<T>& s, std::size_t j, const Batch<T>& m, const TargetBatch<T>& b,
                        const Batch<T>& eps2, Sums<T>& sums) {
  using B = Batch<T>;
  point_law<T, Guard>(B(s.x[j]) - b.x, B(s.y[j]) - b.y, B(s.z[j]) - b.z, m, eps2, sums);
}

// Sources [j0, j1), none of them a target of the batch: two at a time, into
// two sets of sums, so that the adds into the sums do not wait on each other.
template <class T, bool Guard>
inline void batch_points(const SourceParticles<T>& s, std::size_t j0, std::size_t j1, const TargetBatch<T>& b,
                         const Batch<T>& eps2, Sums<T>& s0, Sums<T>& s1) {
  std::size_t j = j0;
  for (; j + 1 < j1; j += 2) {
    batch_point<T, Guard>(s, j, Batch<T>(s.m[j]), b, eps2, s0);
    batch_point<T, Guard>(s, j + 1, Batch<T>(s.m[j + 1]), b, eps2, s1);
  }
  if (j < j1) batch_point<T, Guard>(s, j, Batch<T>(s.m[j]), b, eps2, s0);
}

template <class T, bool Guard>
void particles_on_batch(const SourceParticles<T>& s, const Targets<T>& t, std::size_t begin, const Batch<T>& eps2) {
  using B = Batch<T>;
  constexpr std::size_t W = B::size;
  const TargetBatch<T> b(t, begin);
  Sums<T> s0, s1;
  // Sources [self0, self1) are targets of this batch: source j is lane j − self0.
  std::size_t self0 = s.n, self1 = s.n;
  if (s.self_offset != SourceParticles<T>::npos && s.self_offset < s.n) {
    self0 = s.self_offset + begin < s.n ? s.self_offset + begin : s.n;
    self1 = self0 + W < s.n ? self0 + W : s.n;
  }
  batch_points<T, Guard>(s, 0, self0, b, eps2, s0, s1);
  if (self0 < self1) {
    const B lanes = lane_numbers<T>();
    for (std::size_t j = self0; j < self1; ++j) {
      const B m = xsimd::select(lanes == B(T(j - self0)), B(T(0)), B(s.m[j]));
      batch_point<T, Guard>(s, j, m, b, eps2, (j - self0) % 2 == 0 ? s0 : s1);
    }
  }
  batch_points<T, Guard>(s, self1, s.n, b, eps2, s0, s1);
  store_batch(t, begin, s0, s1, kPointAccelFactor<T>, kPointPotentialFactor<T>);
}

template <class T, bool Guard>
inline void batch_cell(const SourceCells<T>& s, std::size_t j, const TargetBatch<T>& b, const Batch<T>& eps2,
                       Sums<T>& sums) {
  using B = Batch<T>;
  const Quadrupole<Batch<T>> Q{B(s.qxx[j]), B(s.qxy[j]), B(s.qxz[j]), B(s.qyy[j]), B(s.qyz[j]), B(-(s.qxx[j] + s.qyy[j]))};
  quadrupole_law<T, Guard>(B(s.x[j]) - b.x, B(s.y[j]) - b.y, B(s.z[j]) - b.z, B(s.m[j]), Q, eps2, sums);
}

template <class T, bool Guard, bool WithQuadrupole>
void cells_on_batch(const SourceCells<T>& s, const Targets<T>& t, std::size_t begin, const Batch<T>& eps2) {
  const TargetBatch<T> b(t, begin);
  Sums<T> s0, s1;
  if constexpr (WithQuadrupole) {
    std::size_t j = 0;
    for (; j + 1 < s.n; j += 2) {
      batch_cell<T, Guard>(s, j, b, eps2, s0);
      batch_cell<T, Guard>(s, j + 1, b, eps2, s1);
    }
    if (j < s.n) batch_cell<T, Guard>(s, j, b, eps2, s0);
    store_batch(t, begin, s0, s1, T(1), T(1));
  } else {
    const SourceParticles<T> points{s.x, s.y, s.z, s.m, s.n};
    batch_points<T, Guard>(points, 0, s.n, b, eps2, s0, s1);
    store_batch(t, begin, s0, s1, kPointAccelFactor<T>, kPointPotentialFactor<T>);
  }
}

// ---- Sources across the lanes (the last targets, fewer than W) ------------
//
// One target at a time against W sources per step, horizontal sums at the
// end. A last, incomplete batch of sources is copied into a buffer padded
// with massless sources at the target's position (zero quadrupole): their
// terms are exactly 0 (R = ε > 0, or z = 0 by the guard when ε = 0).

// Adds fa · Σ lanes (s0 + s1).a and fp · Σ lanes (s0 + s1).phi to target i.
template <class T>
void store_target(const Targets<T>& t, std::size_t i, const Sums<T>& s0, const Sums<T>& s1, T fa, T fp) {
  t.ax[i] += fa * xsimd::hadd(s0.ax + s1.ax);
  t.ay[i] += fa * xsimd::hadd(s0.ay + s1.ay);
  t.az[i] += fa * xsimd::hadd(s0.az + s1.az);
  t.phi[i] += fp * xsimd::hadd(s0.phi + s1.phi);
}

template <class T, bool Guard>
void particles_on_target(const SourceParticles<T>& s, const Targets<T>& t, std::size_t i, const Batch<T>& eps2) {
  using B = Batch<T>;
  constexpr std::size_t W = B::size;
  const T txs = t.x[i], tys = t.y[i], tzs = t.z[i];
  const B tx(txs), ty(tys), tz(tzs);
  // The source that is this target (npos: none).
  const std::size_t self =
      s.self_offset != SourceParticles<T>::npos && s.self_offset + i < s.n ? s.self_offset + i : s.n;
  Sums<T> sums[2];
  std::size_t jb = 0, k = 0;
  for (; jb + W <= s.n; jb += W, k ^= 1) {
    B m = B::load_unaligned(s.m + jb);
    if (self - jb < W) m = xsimd::select(lane_numbers<T>() == B(T(self - jb)), B(T(0)), m);
    point_law<T, Guard>(B::load_unaligned(s.x + jb) - tx, B::load_unaligned(s.y + jb) - ty,
                        B::load_unaligned(s.z + jb) - tz, m, eps2, sums[k]);
  }
  if (jb < s.n) {
    alignas(64) T x[W], y[W], z[W], m[W];
    for (std::size_t l = 0; l < W; ++l) {
      const bool real = jb + l < s.n && jb + l != self;
      x[l] = real ? s.x[jb + l] : txs;
      y[l] = real ? s.y[jb + l] : tys;
      z[l] = real ? s.z[jb + l] : tzs;
      m[l] = real ? s.m[jb + l] : T(0);
    }
    point_law<T, Guard>(B::load_aligned(x) - tx, B::load_aligned(y) - ty, B::load_aligned(z) - tz,
                        B::load_aligned(m), eps2, sums[k]);
  }
  store_target(t, i, sums[0], sums[1], kPointAccelFactor<T>, kPointPotentialFactor<T>);
}

template <class T, bool Guard, bool WithQuadrupole>
void cells_on_target(const SourceCells<T>& s, const Targets<T>& t, std::size_t i, const Batch<T>& eps2) {
  using B = Batch<T>;
  constexpr std::size_t W = B::size;
  if constexpr (!WithQuadrupole) {
    particles_on_target<T, Guard>(SourceParticles<T>{s.x, s.y, s.z, s.m, s.n}, t, i, eps2);
  } else {
    const T txs = t.x[i], tys = t.y[i], tzs = t.z[i];
    const B tx(txs), ty(tys), tz(tzs);
    Sums<T> sums[2];
    auto add = [&](const T* x, const T* y, const T* z, const T* m, const T* qxx, const T* qxy, const T* qxz,
                   const T* qyy, const T* qyz, Sums<T>& into) {
      const B xx = B::load_unaligned(qxx), yy = B::load_unaligned(qyy);
      const Quadrupole<Batch<T>> Q{xx, B::load_unaligned(qxy), B::load_unaligned(qxz), yy, B::load_unaligned(qyz), -(xx + yy)};
      quadrupole_law<T, Guard>(B::load_unaligned(x) - tx, B::load_unaligned(y) - ty, B::load_unaligned(z) - tz,
                               B::load_unaligned(m), Q, eps2, into);
    };
    std::size_t jb = 0, k = 0;
    for (; jb + W <= s.n; jb += W, k ^= 1)
      add(s.x + jb, s.y + jb, s.z + jb, s.m + jb, s.qxx + jb, s.qxy + jb, s.qxz + jb, s.qyy + jb, s.qyz + jb, sums[k]);
    if (jb < s.n) {
      alignas(64) T x[W], y[W], z[W], m[W], qxx[W], qxy[W], qxz[W], qyy[W], qyz[W];
      for (std::size_t l = 0; l < W; ++l) {
        const bool real = jb + l < s.n;
        x[l] = real ? s.x[jb + l] : txs;
        y[l] = real ? s.y[jb + l] : tys;
        z[l] = real ? s.z[jb + l] : tzs;
        m[l] = real ? s.m[jb + l] : T(0);
        qxx[l] = real ? s.qxx[jb + l] : T(0);
        qxy[l] = real ? s.qxy[jb + l] : T(0);
        qxz[l] = real ? s.qxz[jb + l] : T(0);
        qyy[l] = real ? s.qyy[jb + l] : T(0);
        qyz[l] = real ? s.qyz[jb + l] : T(0);
      }
      add(x, y, z, m, qxx, qxy, qxz, qyy, qyz, sums[k]);
    }
    store_target(t, i, sums[0], sums[1], T(1), T(1));
  }
}

// ---- The kernels -----------------------------------------------------------

// Whether the last `rest` (< W) targets go sources-across: when their source
// steps plus horizontal sums (~2 steps) cost less than one more pass of
// broadcasts over the n sources. Depends on the sizes only.
template <class T>
bool tail_across_sources(std::size_t rest, std::size_t n) {
  constexpr std::size_t W = Batch<T>::size;
  return rest * ((n + W - 1) / W + 2) < n;
}

// Whether ε² is too small for the unguarded 1/√: then zero distances are possible.
template <class T>
bool needs_guard(T eps2) {
  return !(eps2 >= std::numeric_limits<T>::min());
}

// Runs full(targets, begin, first) for every full batch of targets (t and
// its index: first = begin) and, for the last targets, either tail(t, i) per
// target or full() on a padded copy of them (begin = 0, first = the index in
// t of the copy's lane 0).
template <class T, class Full, class Tail>
void for_targets(const Targets<T>& t, std::size_t n_sources, Full&& full, Tail&& tail) {
  constexpr std::size_t W = Batch<T>::size;
  std::size_t begin = 0;
  for (; begin + W <= t.n; begin += W) full(t, begin, begin);
  const std::size_t rest = t.n - begin;
  if (rest == 0) return;
  if (tail_across_sources<T>(rest, n_sources)) {
    for (std::size_t i = begin; i < t.n; ++i) tail(t, i);
    return;
  }
  // A padded batch: the padding lanes repeat the last target, their sums are
  // dropped. Positions are offset so that lane 0 is target `begin`.
  alignas(64) T x[W], y[W], z[W], ax[W] = {}, ay[W] = {}, az[W] = {}, phi[W] = {};
  for (std::size_t k = 0; k < W; ++k) {
    const std::size_t i = k < rest ? begin + k : t.n - 1;
    x[k] = t.x[i];
    y[k] = t.y[i];
    z[k] = t.z[i];
  }
  const Targets<T> padded{x, y, z, ax, ay, az, phi, W};
  full(padded, std::size_t(0), begin);
  for (std::size_t k = 0; k < rest; ++k) {
    t.ax[begin + k] += ax[k];
    t.ay[begin + k] += ay[k];
    t.az[begin + k] += az[k];
    t.phi[begin + k] += phi[k];
  }
}

template <class T, bool Guard>
void particle_field_impl(const SourceParticles<T>& s, const Targets<T>& t, T eps2_value) {
  const Batch<T> eps2(eps2_value);
  for_targets(
      t, s.n,
      [&](const Targets<T>& tt, std::size_t begin, std::size_t first) {
        // Lane k of tt is target first + k, whose own source is self_offset + first + k.
        SourceParticles<T> shifted = s;
        if (s.self_offset != SourceParticles<T>::npos) shifted.self_offset = s.self_offset + first - begin;
        particles_on_batch<T, Guard>(shifted, tt, begin, eps2);
      },
      [&](const Targets<T>& tt, std::size_t i) { particles_on_target<T, Guard>(s, tt, i, eps2); });
}

template <class T, bool Guard, bool WithQuadrupole>
void cell_field_impl(const SourceCells<T>& s, const Targets<T>& t, T eps2_value) {
  const Batch<T> eps2(eps2_value);
  for_targets(
      t, s.n,
      [&](const Targets<T>& tt, std::size_t begin, std::size_t) {
        cells_on_batch<T, Guard, WithQuadrupole>(s, tt, begin, eps2);
      },
      [&](const Targets<T>& tt, std::size_t i) { cells_on_target<T, Guard, WithQuadrupole>(s, tt, i, eps2); });
}

template <class T>
void particle_field_any(const SourceParticles<T>& s, const Targets<T>& t, T eps2) {
  if (needs_guard(eps2))
    particle_field_impl<T, true>(s, t, eps2);
  else
    particle_field_impl<T, false>(s, t, eps2);
}

template <class T>
void cell_field_any(const SourceCells<T>& s, const Targets<T>& t, T eps2, bool quadrupole) {
  const bool guard = needs_guard(eps2);
  if (quadrupole) {
    if (guard)
      cell_field_impl<T, true, true>(s, t, eps2);
    else
      cell_field_impl<T, false, true>(s, t, eps2);
  } else {
    if (guard)
      cell_field_impl<T, true, false>(s, t, eps2);
    else
      cell_field_impl<T, false, false>(s, t, eps2);
  }
}

}  // namespace

void particle_field(const SourceParticles<float>& s, const Targets<float>& t, float eps2) {
  particle_field_any(s, t, eps2);
}
void particle_field(const SourceParticles<double>& s, const Targets<double>& t, double eps2) {
  particle_field_any(s, t, eps2);
}
void cell_field(const SourceCells<float>& s, const Targets<float>& t, float eps2, bool quadrupole) {
  cell_field_any(s, t, eps2, quadrupole);
}
void cell_field(const SourceCells<double>& s, const Targets<double>& t, double eps2, bool quadrupole) {
  cell_field_any(s, t, eps2, quadrupole);
}

}  // namespace swirl::gravity::SWIRL_SIMD_NS

#pragma GCC diagnostic pop
