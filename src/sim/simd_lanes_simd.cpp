// Compiled once per instruction set (CMake: swirl_simd_sources).
#include <xsimd/xsimd.hpp>

namespace swirl::sim::SWIRL_SIMD_NS {

int float_lanes() { return static_cast<int>(xsimd::batch<float>::size); }

}  // namespace swirl::sim::SWIRL_SIMD_NS
