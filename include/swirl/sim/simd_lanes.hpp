// What the SIMD copies of this binary really are: the float lanes of
// xsimd::batch<float> as compiled in each instruction set's copy
// (core/simd_dispatch.hpp), asked of that copy itself. `swirl info` prints
// them, and a test checks them against simd::float_lanes(), so a copy built
// with the wrong flags (say, an "avx512" copy at SSE2 width) is caught.
#pragma once

#include "swirl/core/simd_dispatch.hpp"

namespace swirl::sim {

// Lanes of a float batch in the copy for isa; isa must be compiled in
// (simd::is_compiled), and it is only called if this CPU runs it.
int simd_float_lanes(simd::Isa isa);

}  // namespace swirl::sim
