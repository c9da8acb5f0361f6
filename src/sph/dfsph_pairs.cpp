// Runtime dispatch of DFSPH's pair-pass SIMD bodies (sph/dfsph_pair_kernels.hpp)
// to the copy of simd::active().
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/sph/dfsph_pair_kernels.hpp"

namespace swirl::sph {

// The per-instruction-set copies, compiled from src/sph/dfsph_pairs_simd.cpp.
#define SWIRL_DECLARE_DFSPH_PAIRS_COPY(isa)                                                                       \
  namespace isa {                                                                                                 \
  void dfsph_change_block_simd(const PackedParticles&, const PairBlock&, std::size_t, const std::int32_t*, float*); \
  void dfsph_pressure_block_simd(const PackedParticles&, const PairBlock&, std::size_t, const std::int32_t*,       \
                                 const float*, float, float*, float*, float*);                                     \
  bool dfsph_pairs_simd_fuses();                                                                                  \
  }
SWIRL_SIMD_FOR_EACH_NS(SWIRL_DECLARE_DFSPH_PAIRS_COPY)
#undef SWIRL_DECLARE_DFSPH_PAIRS_COPY

void dfsph_change_block_simd(const PackedParticles& p, const PairBlock& block, std::size_t first,
                             const std::int32_t* kind, float* out) {
  SWIRL_SIMD_DISPATCH(dfsph_change_block_simd, p, block, first, kind, out);
}
void dfsph_pressure_block_simd(const PackedParticles& p, const PairBlock& block, std::size_t first,
                               const std::int32_t* kind, const float* k_over_rho, float dt, float* vx, float* vy,
                               float* vz) {
  SWIRL_SIMD_DISPATCH(dfsph_pressure_block_simd, p, block, first, kind, k_over_rho, dt, vx, vy, vz);
}
bool dfsph_pairs_simd_fuses() { SWIRL_SIMD_DISPATCH(dfsph_pairs_simd_fuses); }

}  // namespace swirl::sph
