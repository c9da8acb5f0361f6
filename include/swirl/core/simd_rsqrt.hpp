// The hardware's estimate of 1/√x for one SIMD copy (core/simd_dispatch.hpp):
// rsqrt14 with AVX-512 (14 bits, float and double), rsqrt with AVX or SSE
// (12 bits, float only). kHasRsqrtEstimate<T> says whether this copy has one;
// where it does not, rsqrt_estimate is the exact 1/√x. Callers refine the
// estimate with Newton steps y ← ½ y (3 − x y²) to the accuracy they need
// (SPH: one step in float; gravity: one in float, two in double).
//
// For the *_simd.cpp kernel files: everything here lives in that copy's
// namespace (SWIRL_SIMD_NS), so that no copy's inline function stands in for
// another's. xsimd::rsqrt is not used: xsimd 8.1 implements it for AVX-512
// with rsqrt28 (AVX-512 ER), which the CPUs swirl runs on do not have.
#pragma once

#include <type_traits>

#include <xsimd/xsimd.hpp>

#if defined(__SSE__) || defined(__AVX__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

#ifndef SWIRL_SIMD_NS
#define SWIRL_SIMD_NS isa_build  // outside swirl_simd_sources (e.g. the header check): the build's own flags
#endif

namespace swirl::simd::SWIRL_SIMD_NS {

template <class T>
inline constexpr bool kHasRsqrtEstimate =
#if defined(__AVX512F__)
    std::is_same_v<T, float> || std::is_same_v<T, double>;
#elif defined(__SSE__)
    std::is_same_v<T, float>;
#else
    false;
#endif

inline xsimd::batch<float> rsqrt_estimate(const xsimd::batch<float>& x) {
#if defined(__AVX512F__)
  static_assert(xsimd::batch<float>::size == 16);
  return xsimd::batch<float>(_mm512_rsqrt14_ps(x));
#elif defined(__AVX__)
  static_assert(xsimd::batch<float>::size == 8);
  return xsimd::batch<float>(_mm256_rsqrt_ps(x));
#elif defined(__SSE__)
  static_assert(xsimd::batch<float>::size == 4);
  return xsimd::batch<float>(_mm_rsqrt_ps(x));
#else
  return xsimd::batch<float>(1.0f) / xsimd::sqrt(x);
#endif
}

inline xsimd::batch<double> rsqrt_estimate(const xsimd::batch<double>& x) {
#if defined(__AVX512F__)
  static_assert(xsimd::batch<double>::size == 8);
  return xsimd::batch<double>(_mm512_rsqrt14_pd(x));
#else
  return xsimd::batch<double>(1.0) / xsimd::sqrt(x);
#endif
}

}  // namespace swirl::simd::SWIRL_SIMD_NS
