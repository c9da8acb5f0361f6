// A small deterministic random number generator for initial conditions.
//
// splitmix64 (Steele, Lea and Flood 2014), written out here because the
// standard library's distributions differ between implementations, and the
// same seed must give the same particles on every machine.
#pragma once

#include <cstdint>

namespace swirl {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15u);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
  }

  // Uniform in [0, 1): the top 53 bits, so every value is exact in a double.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }

 private:
  std::uint64_t state_;
};

}  // namespace swirl
