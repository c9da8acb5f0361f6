#include "swirl/sim/simd_lanes.hpp"

#include <stdexcept>
#include <string>

namespace swirl::sim {

#define SWIRL_DECLARE_COPY(ns) \
  namespace ns {               \
  int float_lanes();           \
  }
SWIRL_SIMD_FOR_EACH_NS(SWIRL_DECLARE_COPY)
#undef SWIRL_DECLARE_COPY

int simd_float_lanes(simd::Isa isa) {
  if (!simd::usable(isa))
    throw std::invalid_argument("SIMD instruction set " + std::string(simd::isa_name(isa)) + " is not usable here");
  SWIRL_SIMD_DISPATCH_TO(isa, float_lanes, );
}

}  // namespace swirl::sim
