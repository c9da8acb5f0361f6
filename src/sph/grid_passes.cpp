// Runtime dispatch of the SPH grid passes' SIMD cell bodies
// (sph/grid_pass_kernels.hpp) to the copy of simd::active().
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/sph/grid_pass_kernels.hpp"

namespace swirl::sph {

// The per-instruction-set copies, compiled from src/sph/grid_passes_simd.cpp.
#define SWIRL_DECLARE_GRID_PASS_COPY(isa)                                                                            \
  namespace isa {                                                                                                    \
  std::uint64_t density_cell_simd(const DensityKernelArgs<float>&, std::size_t, std::size_t, const IndexRange*, \
                                  int);                                                                              \
  std::uint64_t density_cell_simd(const DensityKernelArgs<double>&, std::size_t, std::size_t, const IndexRange*, \
                                  int);                                                                              \
  void forces_cell_simd(const ForceKernelArgs<float>&, std::size_t, std::size_t, const IndexRange*, int);        \
  void forces_cell_simd(const ForceKernelArgs<double>&, std::size_t, std::size_t, const IndexRange*, int);       \
  int grid_pass_float_lanes();                                                                                       \
  }
SWIRL_SIMD_FOR_EACH_NS(SWIRL_DECLARE_GRID_PASS_COPY)
#undef SWIRL_DECLARE_GRID_PASS_COPY

std::uint64_t density_cell_simd(const DensityKernelArgs<float>& a, std::size_t first, std::size_t last,
                                const IndexRange* ranges, int count) {
  SWIRL_SIMD_DISPATCH(density_cell_simd, a, first, last, ranges, count);
}
std::uint64_t density_cell_simd(const DensityKernelArgs<double>& a, std::size_t first, std::size_t last,
                                const IndexRange* ranges, int count) {
  SWIRL_SIMD_DISPATCH(density_cell_simd, a, first, last, ranges, count);
}
void forces_cell_simd(const ForceKernelArgs<float>& a, std::size_t first, std::size_t last,
                      const IndexRange* ranges, int count) {
  SWIRL_SIMD_DISPATCH(forces_cell_simd, a, first, last, ranges, count);
}
void forces_cell_simd(const ForceKernelArgs<double>& a, std::size_t first, std::size_t last,
                      const IndexRange* ranges, int count) {
  SWIRL_SIMD_DISPATCH(forces_cell_simd, a, first, last, ranges, count);
}
int grid_pass_float_lanes() { SWIRL_SIMD_DISPATCH(grid_pass_float_lanes); }

}  // namespace swirl::sph
