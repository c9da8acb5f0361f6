#include "swirl/gravity/bench.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "swirl/core/phase_timers.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/integrate/velocity_verlet.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {
// The stepper's update (sim/simulation.hpp) without the stepper, which sits
// above this module: drift x += v·Δt + ½a·Δt², forces, kick v += ½(a_prev + a)·Δt.
template <class Real>
BenchResult run(const BenchSettings& b) {
  GravitySettings g;
  g.method = b.method;
  g.scheme = b.scheme;
  g.opening = b.opening;
  g.softening = b.softening;
  GravityForce<Real> gravity(g);
  ParticleSet<Real> p = plummer<Real>(b.n, b.seed);
  constexpr std::size_t block = 1024;
  PhaseTimers timers;
  const ForceContext ctx{0, block, &timers};
  gravity.add_acceleration(p, ctx);  // a₀, not timed
  timers = PhaseTimers{};
  const Real dt = Real(b.dt);
  const auto t0 = std::chrono::steady_clock::now();
  for (int it = 0; it < b.iterations; ++it) {
    {
      ScopedPhase phase(timers, "update");
      parallel::for_blocks("bench_drift", p.size(), block, [&](std::size_t begin, std::size_t end, std::size_t) {
        integrate::drift(p, begin, end, dt);
        for (int a = 0; a < 3; ++a) std::fill(p.acceleration[a].begin() + std::ptrdiff_t(begin),
                                              p.acceleration[a].begin() + std::ptrdiff_t(end), Real(0));
      });
    }
    gravity.add_acceleration(p, ctx);
    ScopedPhase phase(timers, "update");
    parallel::for_blocks("bench_kick", p.size(), block,
                         [&](std::size_t begin, std::size_t end, std::size_t) { integrate::kick(p, begin, end, dt); });
  }
  BenchResult r;
  r.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.tree_build = timers.seconds("forces.tree_build");
  r.force = timers.seconds("forces.walk");
  r.update = timers.seconds("update");
  r.mean_nodes_visited = gravity.stats().mean_nodes_visited;
  r.trees = gravity.stats().trees;
  r.nodes = gravity.stats().nodes;
  return r;
}
}  // namespace

BenchResult time_iterations(const BenchSettings& b) {
  if (b.n == 0) throw std::invalid_argument("gravity bench: the particle count must be at least 1");
  if (b.iterations < 1) throw std::invalid_argument("gravity bench: iterations must be at least 1");
  if (b.threads < 1) throw std::invalid_argument("gravity bench: threads must be at least 1");
  const int previous = parallel::thread_count();
  parallel::set_thread_count(b.threads);
  struct Restore {
    int threads;
    ~Restore() { parallel::set_thread_count(threads); }
  } restore{previous};
  return b.single_precision ? run<float>(b) : run<double>(b);
}

}  // namespace swirl::gravity
