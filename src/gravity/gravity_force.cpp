#include "swirl/gravity/gravity_force.hpp"

#include <chrono>

#include "swirl/gravity/direct_sum.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

template <class Real>
GravityForce<Real>::GravityForce(const GravitySettings& settings) : settings_(settings), tree_(settings) {}

template <class Real>
void GravityForce<Real>::add_acceleration(ParticleSet<Real>& p, const ForceContext& ctx) {
  if (settings_.method == Method::direct) {
    const auto t0 = std::chrono::steady_clock::now();
    direct_sum(p, Real(settings_.softening), ctx.block_size, field_);
    stats_ = GravityStats{};
    stats_.mean_nodes_visited = p.empty() ? 0.0 : double(p.size() - 1);
    stats_.force_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  } else {
    if (settings_.reorder)
      tree_.compute_reordering(p, field_, ctx.block_size);  // reorders p with the linear tree
    else
      tree_.compute(p, field_, ctx.block_size);
    stats_ = tree_.stats();
  }
  const std::size_t phi_field = p.add_field("potential", 1);
  Real* phi = p.extra(phi_field).data();
  parallel::for_blocks("gravity_add", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    for (int a = 0; a < 3; ++a) {
      Real* acc = p.acceleration[a].data();
      const Real* add = field_.acceleration[a].data();
#pragma omp simd
      for (std::size_t i = b; i < e; ++i) acc[i] += add[i];
    }
    for (std::size_t i = b; i < e; ++i) phi[i] = field_.potential[i];
  });
  if (ctx.timers) {
    ctx.timers->add("forces.tree_build", stats_.tree_build_seconds);
    ctx.timers->add("forces.walk", stats_.force_seconds);
  }
}

template class GravityForce<float>;
template class GravityForce<double>;

}  // namespace swirl::gravity
