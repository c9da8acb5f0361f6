#include "swirl/gravity/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "swirl/core/phase_timers.hpp"
#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/integrate/kick_drift.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {
// The paper's tree (the paper's tables measure it; bh-scale measures the linear one).
GravitySettings paper_tree(Scheme scheme, const SplitRules& splits, double opening, double softening) {
  GravitySettings g;
  g.scheme = scheme;
  g.subdomain_split = splits.subdomain;
  g.subtree_split = splits.subtree;
  g.upper_nodes = splits.upper_nodes;
  g.tree = Tree::Paper;
  g.opening = opening;
  g.softening = softening;
  return g;
}

// The paper's time step: velocity Verlet (the simulation's stepper,
// integrate/kick_drift.hpp) around one gravity evaluation; "update" is the
// stepper's own time (drift, zeroing a, kick).
template <class Real>
class GravityOnly final : public integrate::Forces {
 public:
  GravityOnly(GravityForce<Real>& gravity, ParticleSet<Real>& p, std::size_t block, PhaseTimers& timers)
      : gravity_(gravity), p_(p), block_(block), timers_(timers) {}
  void evaluate(double time) override {
    {
      ScopedPhase phase(timers_, "integrate");
      parallel::for_blocks("bench_zero", p_.size(), block_, [&](std::size_t begin, std::size_t end, std::size_t) {
        for (int a = 0; a < 3; ++a)
          std::fill(p_.acceleration[a].begin() + std::ptrdiff_t(begin), p_.acceleration[a].begin() + std::ptrdiff_t(end),
                    Real(0));
      });
    }
    gravity_.add_acceleration(p_, SolverContext<Real>{time, block_, &timers_, nullptr, {}, nullptr});
  }

 private:
  GravityForce<Real>& gravity_;
  ParticleSet<Real>& p_;
  std::size_t block_;
  PhaseTimers& timers_;
};

template <class Real>
BenchResult run(const BenchSettings& b) {
  GravitySettings g = paper_tree(b.scheme, b.splits, b.opening, b.softening);
  g.method = b.method;
  GravityForce<Real> gravity(g);
  ParticleSet<Real> p = plummer<Real>(b.n, b.seed);
  constexpr std::size_t block = 1024;
  PhaseTimers timers;
  GravityOnly<Real> forces(gravity, p, block, timers);
  integrate::KickDriftStepper<Real> stepper(integrate::Method::VelocityVerlet);
  gravity.declare_fields(p);
  stepper.start(p, forces, 0, block);  // a₀, not timed
  timers = PhaseTimers{};
  integrate::StepRequest request;
  request.dt = b.dt;
  request.block_size = block;
  request.scan = false;  // the paper's loop has no guard
  request.timers = &timers;
  const auto t0 = std::chrono::steady_clock::now();
  for (int it = 0; it < b.iterations; ++it) {
    request.t_next = double(it + 1) * b.dt;
    stepper.advance(p, forces, request);
  }
  BenchResult r;
  r.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.tree_build = timers.seconds("forces.tree_build");
  r.force = timers.seconds("forces.walk");
  r.update = timers.seconds("integrate");
  r.mean_nodes_visited = gravity.stats().mean_nodes_visited;
  r.trees = gravity.stats().trees;
  r.nodes = gravity.stats().nodes;
  return r;
}

constexpr std::size_t kBlock = 1024;

// Sets the thread count for its lifetime and restores the previous one.
struct ThreadScope {
  explicit ThreadScope(int threads) : previous(parallel::thread_count()) { parallel::set_thread_count(threads); }
  ~ThreadScope() { parallel::set_thread_count(previous); }
  ThreadScope(const ThreadScope&) = delete;
  ThreadScope& operator=(const ThreadScope&) = delete;
  int previous;
};

void check(const BenchSettings& b) {
  if (b.n == 0) throw std::invalid_argument("gravity bench: the particle count must be at least 1");
  if (b.iterations < 1) throw std::invalid_argument("gravity bench: iterations must be at least 1");
  if (b.threads < 1) throw std::invalid_argument("gravity bench: threads must be at least 1");
}

template <class Real>
std::vector<ForceError> errors_of(const BenchSettings& b, const std::vector<ForceErrorCase>& cases) {
  const ParticleSet<Real> p = plummer<Real>(b.n, b.seed);
  // The reference in double from the same (possibly rounded) positions.
  ParticleSet<double> pd(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int a = 0; a < 3; ++a) pd.position[a][i] = double(p.position[a][i]);
    pd.mass[i] = double(p.mass[i]);
  }
  GravityField<double> exact;
  direct_sum(pd, b.softening, kBlock, exact);
  std::vector<ForceError> out;
  out.reserve(cases.size());
  std::vector<double> e(p.size());
  for (const ForceErrorCase& c : cases) {
    BarnesHut<Real> tree(paper_tree(c.scheme, c.splits, c.opening, b.softening));
    GravityField<Real> field;
    tree.compute(p, field, kBlock);
    parallel::for_blocks("bench_force_error", p.size(), kBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
      for (std::size_t i = begin; i < end; ++i) {
        double d2 = 0, r2 = 0;
        for (int a = 0; a < 3; ++a) {
          const double d = double(field.acceleration[a][i]) - exact.acceleration[a][i];
          d2 += d * d;
          r2 += exact.acceleration[a][i] * exact.acceleration[a][i];
        }
        e[i] = r2 > 0 ? std::sqrt(d2 / r2) : std::sqrt(d2);
      }
    });
    ForceError r = summarize_errors(e);
    r.mean_nodes_visited = tree.stats().mean_nodes_visited;
    out.push_back(r);
  }
  return out;
}
}  // namespace

BenchResult time_iterations(const BenchSettings& b) {
  check(b);
  const ThreadScope threads(b.threads);
  return b.single_precision ? run<float>(b) : run<double>(b);
}

ForceError summarize_errors(std::vector<double>& errors) {
  ForceError r;
  if (errors.empty()) return r;
  std::sort(errors.begin(), errors.end());
  const std::size_t n = errors.size();
  r.median = errors[(n - 1) / 2];
  const auto rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(n)));
  r.p99 = errors[std::max<std::size_t>(rank, 1) - 1];
  r.max = errors.back();
  return r;
}

std::vector<ForceError> force_errors(const BenchSettings& b, const std::vector<ForceErrorCase>& cases) {
  check(b);
  for (const ForceErrorCase& c : cases) validate(paper_tree(c.scheme, c.splits, c.opening, b.softening));
  const ThreadScope threads(b.threads);
  return b.single_precision ? errors_of<float>(b, cases) : errors_of<double>(b, cases);
}

}  // namespace swirl::gravity
