// UniformGravity: a constant external acceleration g (m/s²) on every particle,
// the f_external/ρ term of the thesis's eq. 2.7 for a uniform field.
#pragma once

#include "swirl/core/vec3.hpp"
#include "swirl/force/force_model.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl {

template <class Real>
class UniformGravity final : public ForceModel<Real> {
 public:
  explicit UniformGravity(Vec3<Real> g) : g_(g) {}

  std::string_view name() const override { return "gravity"; }

  void add_acceleration(ParticleSet<Real>& p, const ForceContext& ctx) override {
    Real* ax = p.acceleration.x.data();
    Real* ay = p.acceleration.y.data();
    Real* az = p.acceleration.z.data();
    const Vec3<Real> g = g_;
    const std::size_t n = p.size();
    parallel::for_blocks_pinned("uniform_gravity", n, ctx.block_size, [=](std::size_t b, std::size_t e, std::size_t) {
#pragma omp simd
      for (std::size_t i = b; i < e; ++i) {
        ax[i] += g.x;
        ay[i] += g.y;
        az[i] += g.z;
      }
    });
  }

  const Vec3<Real>& g() const { return g_; }

 private:
  Vec3<Real> g_;
};

}  // namespace swirl
