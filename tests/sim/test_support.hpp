// Helpers shared by the simulation tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "swirl/core/particle_set.hpp"
#include "swirl/force/force_model.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::testing {

// a = -ω²·(x - centre): a harmonic oscillator about `centre` on every axis.
template <class Real>
class Spring final : public ForceModel<Real> {
 public:
  Spring(Real omega, Real centre) : omega2_(omega * omega), centre_(centre) {}
  std::string_view name() const override { return "spring"; }
  void add_acceleration(ParticleSet<Real>& p, const ForceContext& ctx) override {
    parallel::for_blocks("spring", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (int axis = 0; axis < 3; ++axis)
        for (std::size_t i = b; i < e; ++i) p.acceleration[axis][i] += -omega2_ * (p.position[axis][i] - centre_);
    });
  }

 private:
  Real omega2_, centre_;
};

// A deterministic pseudo-random number in [0, 1) from an integer.
inline double hash01(std::uint64_t k) {
  k += 0x9e3779b97f4a7c15ull;
  k = (k ^ (k >> 30)) * 0xbf58476d1ce4e5b9ull;
  k = (k ^ (k >> 27)) * 0x94d049bb133111ebull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53;
}

}  // namespace swirl::testing
