// The explicit-SIMD bodies of DFSPH's solve passes over kept pairs
// (sph/dfsph_pair_kernels.hpp). Compiled once per instruction set by CMake's
// swirl_simd_sources(); everything lives in namespace SWIRL_SIMD_NS, so that
// no inline function of one copy can stand in for another's
// (tools/check_simd_objects.sh). A particle's packed data is one 4-lane
// float vector (SSE registers in every x86-64 copy; the wider copies use
// their VEX/EVEX encodings and, with AVX2/AVX-512, FMA); off x86-64 the
// `generic` copy runs the scalar twin's arithmetic on the packed data.
#include <cstddef>
#include <cstdint>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "swirl/core/particle_kind.hpp"
#include "swirl/sph/dfsph_pair_kernels.hpp"

namespace swirl::sph::SWIRL_SIMD_NS {

namespace {

#if defined(__FMA__)
constexpr bool kFuses = true;
#else
constexpr bool kFuses = false;
#endif

// a·b + c: one rounding with FMA, two without (sph/dfsph_terms.hpp's fused()).
inline float fused_scalar(float a, float b, float c) {
#if defined(__FMA__)
  return _mm_cvtss_f32(_mm_fmadd_ss(_mm_set_ss(a), _mm_set_ss(b), _mm_set_ss(c)));
#else
  return a * b + c;
#endif
}

// Calls one(k) or two(k, l) for the fluid particles of the block, two at a
// time while there are two (sph/dfsph_pairs.hpp's detail::fluid_in_twos).
template <class Boundary, class One, class Two>
inline void fluid_in_twos(std::size_t count, Boundary&& boundary, One&& one, Two&& two) {
  std::size_t waiting = count;
  for (std::size_t k = 0; k < count; ++k) {
    if (boundary(k)) continue;
    if (waiting == count) {
      waiting = k;
    } else {
      two(waiting, k);
      waiting = count;
    }
  }
  if (waiting != count) one(waiting);
}

// Calls first(q) for q in [q, end) and second(q2) for q2 in [q2, end2), each
// in its order, interleaved while both last (sph/dfsph_pairs.hpp's
// detail::side_by_side, with offsets).
template <class First, class Second>
inline void side_by_side(std::size_t q, std::size_t end, std::size_t q2, std::size_t end2, First&& first,
                         Second&& second) {
  for (; q < end && q2 < end2; ++q, ++q2) {
    first(q);
    second(q2);
  }
  for (; q < end; ++q) first(q);
  for (; q2 < end2; ++q2) second(q2);
}

#if defined(__SSE2__)

using V = __m128;

inline V fmadd(V a, V b, V c) {
#if defined(__FMA__)
  return _mm_fmadd_ps(a, b, c);
#else
  return _mm_add_ps(_mm_mul_ps(a, b), c);
#endif
}
inline V fmadd_lane0(V a, V b, V c) {
#if defined(__FMA__)
  return _mm_fmadd_ss(a, b, c);
#else
  return _mm_add_ss(_mm_mul_ss(a, b), c);
#endif
}
// Lane k gets lane k + 1 (lane 3 gets 0).
inline V down(V a) { return _mm_castsi128_ps(_mm_srli_si128(_mm_castps_si128(a), 4)); }
inline V lane3(V a) { return _mm_shuffle_ps(a, a, 0xFF); }
inline float lane(V a, int k) {
  switch (k) {
    case 1: return _mm_cvtss_f32(_mm_shuffle_ps(a, a, 0x55));
    case 2: return _mm_cvtss_f32(_mm_shuffle_ps(a, a, 0xAA));
    default: return _mm_cvtss_f32(a);
  }
}

// Lane 0 of sum + m_j g (v_i − v_j)·r⃗_ij, with xi, vi = particle i's packed
// {z, x, y, m} and {v_z, v_x, v_y, 0}: the dot product as Δv_z r_z + (Δv_x r_x + Δv_y r_y)
// (sph/dfsph_terms.hpp's velocity_dot), lane by lane.
inline V change_term(V sum, V xi, V vi, const float* xm, const float* v, std::uint32_t j, const float* g) {
  const V xj = _mm_load_ps(xm + 4 * std::size_t(j));
  const V dr = _mm_sub_ps(xi, xj);                            // {r_z, r_x, r_y, ·}
  const V dv = _mm_sub_ps(vi, _mm_load_ps(v + 4 * std::size_t(j)));  // {Δv_z, Δv_x, Δv_y, 0}
  const V yy = _mm_mul_ps(dv, dr);                            // lane 2: Δv_y r_y
  const V xy = fmadd(dv, dr, down(yy));                       // lane 1: Δv_x r_x + Δv_y r_y
  const V dot = fmadd(dv, dr, down(xy));                      // lane 0: Δv_z r_z + that
  const V weight = _mm_mul_ss(lane3(xj), _mm_load_ss(g));     // lane 0: m_j g
  return fmadd_lane0(weight, dot, sum);
}

// a + m_j (k_i + k_j) g r⃗_ij in lanes 0–2 (z, x, y).
inline V pressure_term(V a, V xi, float ki, const float* xm, const float* k_over_rho, std::uint32_t j,
                       const float* g) {
  const V xj = _mm_load_ps(xm + 4 * std::size_t(j));
  const V dr = _mm_sub_ps(xi, xj);
  const V weight = _mm_mul_ps(_mm_mul_ps(lane3(xj), _mm_set1_ps(ki + k_over_rho[j])), _mm_set1_ps(*g));
  return fmadd(weight, dr, a);
}

#endif

}  // namespace

void dfsph_change_block_simd(const PackedParticles& p, const PairBlock& block, std::size_t first,
                             const std::int32_t* kind, float* out) {
  const auto begin = [&](std::size_t k) -> std::size_t { return k == 0 ? 0 : block.ends[k - 1]; };
  const auto boundary = [&](std::size_t k) {
    if (!kind || !is_boundary(kind[first + k])) return false;
    out[first + k] = 0;
    return true;
  };
#if defined(__SSE2__)
  const float *xm = p.xm, *v = p.v;
  const auto one = [&](std::size_t k) {
    const std::size_t i = first + k;
    const V xi = _mm_load_ps(xm + 4 * i), vi = _mm_load_ps(v + 4 * i);
    V sum = _mm_setzero_ps();
    for (std::size_t q = begin(k); q < block.ends[k]; ++q) sum = change_term(sum, xi, vi, xm, v, block.j[q], block.g + q);
    out[i] = _mm_cvtss_f32(sum);
  };
  const auto two = [&](std::size_t k, std::size_t l) {
    const std::size_t i = first + k, i2 = first + l;
    const V xi = _mm_load_ps(xm + 4 * i), vi = _mm_load_ps(v + 4 * i);
    const V xi2 = _mm_load_ps(xm + 4 * i2), vi2 = _mm_load_ps(v + 4 * i2);
    V sum = _mm_setzero_ps(), sum2 = _mm_setzero_ps();
    side_by_side(
        begin(k), block.ends[k], begin(l), block.ends[l],
        [&](std::size_t q) { sum = change_term(sum, xi, vi, xm, v, block.j[q], block.g + q); },
        [&](std::size_t q) { sum2 = change_term(sum2, xi2, vi2, xm, v, block.j[q], block.g + q); });
    out[i] = _mm_cvtss_f32(sum);
    out[i2] = _mm_cvtss_f32(sum2);
  };
#else
  const auto one = [&](std::size_t k) {
    const std::size_t i = first + k;
    const float* xi = p.xm + 4 * i;
    const float* vi = p.v + 4 * i;
    float sum = 0;
    for (std::size_t q = begin(k); q < block.ends[k]; ++q) {
      const float* xj = p.xm + 4 * std::size_t(block.j[q]);
      const float* vj = p.v + 4 * std::size_t(block.j[q]);
      const float dot = fused_scalar(vi[0] - vj[0], xi[0] - xj[0],
                                     fused_scalar(vi[1] - vj[1], xi[1] - xj[1], (vi[2] - vj[2]) * (xi[2] - xj[2])));
      sum = fused_scalar(xj[3] * block.g[q], dot, sum);
    }
    out[i] = sum;
  };
  const auto two = [&](std::size_t k, std::size_t l) {
    one(k);
    one(l);
  };
#endif
  fluid_in_twos(block.count, boundary, one, two);
}

void dfsph_pressure_block_simd(const PackedParticles& p, const PairBlock& block, std::size_t first,
                               const std::int32_t* kind, const float* k_over_rho, float dt, float* vx, float* vy,
                               float* vz) {
  const auto begin = [&](std::size_t k) -> std::size_t { return k == 0 ? 0 : block.ends[k - 1]; };
  const auto boundary = [&](std::size_t k) { return kind && is_boundary(kind[first + k]); };
  // v_i −= dt·a, as the scalar twin: one rounding of v_i − dt·a where it fuses.
  const auto apply = [&](std::size_t i, float az, float ax, float ay) {
    vx[i] = fused_scalar(-dt, ax, vx[i]);
    vy[i] = fused_scalar(-dt, ay, vy[i]);
    vz[i] = fused_scalar(-dt, az, vz[i]);
  };
#if defined(__SSE2__)
  const float* xm = p.xm;
  const auto one = [&](std::size_t k) {
    const std::size_t i = first + k;
    const V xi = _mm_load_ps(xm + 4 * i);
    const float ki = k_over_rho[i];
    V a = _mm_setzero_ps();
    for (std::size_t q = begin(k); q < block.ends[k]; ++q)
      a = pressure_term(a, xi, ki, xm, k_over_rho, block.j[q], block.g + q);
    apply(i, lane(a, 0), lane(a, 1), lane(a, 2));
  };
  const auto two = [&](std::size_t k, std::size_t l) {
    const std::size_t i = first + k, i2 = first + l;
    const V xi = _mm_load_ps(xm + 4 * i), xi2 = _mm_load_ps(xm + 4 * i2);
    const float ki = k_over_rho[i], ki2 = k_over_rho[i2];
    V a = _mm_setzero_ps(), a2 = _mm_setzero_ps();
    side_by_side(
        begin(k), block.ends[k], begin(l), block.ends[l],
        [&](std::size_t q) { a = pressure_term(a, xi, ki, xm, k_over_rho, block.j[q], block.g + q); },
        [&](std::size_t q) { a2 = pressure_term(a2, xi2, ki2, xm, k_over_rho, block.j[q], block.g + q); });
    apply(i, lane(a, 0), lane(a, 1), lane(a, 2));
    apply(i2, lane(a2, 0), lane(a2, 1), lane(a2, 2));
  };
#else
  const auto one = [&](std::size_t k) {
    const std::size_t i = first + k;
    const float* xi = p.xm + 4 * i;
    const float ki = k_over_rho[i];
    float a[3] = {0, 0, 0};
    for (std::size_t q = begin(k); q < block.ends[k]; ++q) {
      const std::size_t j = block.j[q];
      const float* xj = p.xm + 4 * j;
      const float weight = xj[3] * (ki + k_over_rho[j]) * block.g[q];
      for (int c = 0; c < 3; ++c) a[c] = fused_scalar(weight, xi[c] - xj[c], a[c]);
    }
    apply(i, a[0], a[1], a[2]);
  };
  const auto two = [&](std::size_t k, std::size_t l) {
    one(k);
    one(l);
  };
#endif
  fluid_in_twos(block.count, boundary, one, two);
}

bool dfsph_pairs_simd_fuses() { return kFuses; }

}  // namespace swirl::sph::SWIRL_SIMD_NS
