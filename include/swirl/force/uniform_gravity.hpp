// UniformGravity: a constant external acceleration g on every particle, the
// f_external/ρ term of the thesis's eq. 2.7 for a uniform field (m/s² in SI).
// Its potential energy is U = −Σ m_i g·x_i (zero at the origin), over the
// particles that can move: static boundary particles (core/particle_kind.hpp),
// whose "mass" is a volume weight, are left out.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "swirl/core/particle_kind.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl {

template <class Real>
class UniformGravity final : public Solver<Real> {
 public:
  explicit UniformGravity(Vec3<Real> g) : g_(g) {}
  std::string_view name() const override { return "gravity"; }

  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
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

  // U = −Σ m g·x over the fluid, summed in double in the one-rank block order
  // (dist::BlockFold): the same bits for any thread and rank count.
  double potential_energy(const ParticleSet<Real>& p, const dist::BlockFold& fold) const override {
    const Vec3d g = g_.template cast<double>();
    const std::size_t k = p.find_int_field(kKindField);
    const std::int32_t* kind = k == ParticleSet<Real>::npos ? nullptr : p.int_field(k).data();
    return fold("uniform_gravity_energy", p.size(), std::array{dist::FoldOp::Sum},
                [&](std::size_t i, std::array<double, 1>& u) {
                  if (kind && is_boundary(kind[i])) return false;
                  u[0] = -(double(p.mass[i]) * (g.x * double(p.position.x[i]) + g.y * double(p.position.y[i]) +
                                                g.z * double(p.position.z[i])));
                  return true;
                })[0];
  }

  const Vec3<Real>& g() const { return g_; }
  // A new field from the next evaluation on (swirl view's slider), between steps.
  void set_g(const Vec3<Real>& g) { g_ = g; }

 private:
  Vec3<Real> g_;
};

}  // namespace swirl
