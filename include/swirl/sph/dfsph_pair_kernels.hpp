// The explicit-SIMD bodies of DFSPH's two solve passes over kept pairs
// (sph/dfsph_pairs.hpp), float only, behind runtime dispatch
// (core/simd_dispatch.hpp): src/sph/dfsph_pairs_simd.cpp is compiled once per
// instruction set and the functions below call the copy of simd::active().
//
// What makes them faster than the scalar loops (their twins): a particle's
// data is read as one 16-byte vector instead of three or four scalars. The
// scalar pair loop loads nine values a pair (j, g, and seven of j's: x, y, z,
// v⃗, m), and those loads, not the bytes streamed or the arithmetic, bound it
// (docs/performance/dfsph.md). With j's position and mass packed as
// {z, x, y, m} and its velocity as {v_z, v_x, v_y, 0} (PackedParticles), a
// pair of the density change loads j, g and two vectors; one of the pressure
// pass loads j, g, one vector and k_j.
//
// Same bits as the scalar twins within a build whose scalar code fuses
// multiply-adds the same way (sph/dfsph_terms.hpp): each lane computes what
// the scalar code computes, in its order — the dot product (v_i − v_j)·r⃗_ij
// as Δv_z r_z + (Δv_x r_x + Δv_y r_y) by shifting the partial results across
// lanes, and every sum in its list's order. The AVX2 and AVX-512 copies fuse
// (FMA); the SSE2 copy cannot, and rounds a·b + c twice, as scalar code built
// without FMA does. Two particles' lists run side by side, as in the scalar
// loops, so that two chains of multiply-adds are in flight.
// Units: as dfsph_passes.hpp.
#pragma once

#include <cstddef>
#include <cstdint>

namespace swirl::sph {

// Per particle of a set, 16-byte aligned: xm = {z, x, y, m} (fixed while the
// pairs are valid: positions and masses do not change during the solves) and
// v = {v_z, v_x, v_y, 0} (packed again at each density-change pass).
struct PackedParticles {
  const float* xm = nullptr;
  const float* v = nullptr;
};

// One block's lists: particle k of the block (k in [0, count)) has the pairs
// [k == 0 ? 0 : ends[k − 1], ends[k]) of j and g.
struct PairBlock {
  const std::uint32_t* ends = nullptr;
  const std::uint32_t* j = nullptr;
  const float* g = nullptr;
  std::size_t count = 0;
};

// out[i] = Σ_j m_j g_ij (v_i − v_j)·r⃗_ij for the block's particles i = first + k
// (0 for a boundary particle: kind null or is_boundary(kind[i])).
void dfsph_change_block_simd(const PackedParticles& p, const PairBlock& block, std::size_t first,
                             const std::int32_t* kind, float* out);

// v_i −= dt Σ_j m_j (k_i + k_j) g_ij r⃗_ij for the block's fluid particles i = first + k.
void dfsph_pressure_block_simd(const PackedParticles& p, const PairBlock& block, std::size_t first,
                               const std::int32_t* kind, const float* k_over_rho, float dt, float* vx, float* vy,
                               float* vz);

// Whether the copy the passes now run fuses multiply-adds (AVX2, AVX-512: FMA).
bool dfsph_pairs_simd_fuses();

}  // namespace swirl::sph
