// Each SIMD copy of the binary is built for its instruction set: its float
// batch has the lanes that set promises (catches a copy built with the wrong
// -march, or a dispatcher that calls the wrong copy).
#include <cstdlib>

#include <gtest/gtest.h>

#include "swirl/core/simd_dispatch.hpp"
#include "swirl/sim/simd_lanes.hpp"

namespace swirl::sim {
namespace {

TEST(SimdLanes, EveryCopyTheCpuRunsHasItsWidth) {
  int checked = 0;
  for (simd::Isa isa : simd::kCompiledIsas) {
    if (!simd::cpu_supports(isa)) continue;
    const int expected = simd::float_lanes(isa);
    if (expected == 0) continue;  // generic: the build's own width
    EXPECT_EQ(simd_float_lanes(isa), expected) << simd::isa_name(isa);
    ++checked;
  }
#if defined(__x86_64__)
  EXPECT_GE(checked, 1);  // sse2 at least
#endif
}

TEST(SimdLanes, ActiveIsTheWidestTheCpuRunsUnlessChosen) {
  if (std::getenv("SWIRL_SIMD") == nullptr) {
    EXPECT_EQ(simd::active(), simd::best_supported());
  }
  for (simd::Isa isa : simd::kCompiledIsas) {
    if (!simd::usable(isa)) continue;
    simd::ScopedIsa scope(isa);
    EXPECT_EQ(simd::active(), isa);
  }
}

TEST(SimdLanes, UnusableCopiesAreRefused) {
  for (simd::Isa isa : {simd::Isa::Generic, simd::Isa::Sse2, simd::Isa::Avx2, simd::Isa::Avx512})
    if (!simd::usable(isa)) {
      EXPECT_THROW(simd_float_lanes(isa), std::invalid_argument);
      EXPECT_THROW(simd::set_active(isa), std::invalid_argument);
    }
}

}  // namespace
}  // namespace swirl::sim
