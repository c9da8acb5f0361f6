// Google Benchmark for the gravity solver (Demiroz et al. 2011, section 5).
//
//   BM_Force   one force evaluation (tree build + walks) of a Plummer sphere,
//              per scheme, N and thread count, with the nodes visited per particle;
//   BM_Table2  the paper's experiment: 50 iterations of force + leapfrog update,
//              λ = 0.5, N = 1024 … 32768, reported as the total time (compare
//              Table 2) with the phases of Table 1 as counters (seconds).
//
// Run e.g.  gravity_bench --benchmark_filter=Table2
#include <benchmark/benchmark.h>

#include <array>
#include <string>

#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/bench.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace {

using namespace swirl::gravity;
constexpr std::array<Scheme, 3> kSchemes{Scheme::subdomain, Scheme::subtree, Scheme::global};

template <class Real>
void force(benchmark::State& state) {
  const Scheme scheme = kSchemes[std::size_t(state.range(0))];
  const auto n = std::size_t(state.range(1));
  const int saved = swirl::parallel::thread_count();
  swirl::parallel::set_thread_count(int(state.range(2)));
  GravitySettings s;
  s.scheme = scheme;
  BarnesHut<Real> tree(s);
  const auto particles = plummer<Real>(n, 1);
  GravityField<Real> field;
  double build = 0;
  for (auto _ : state) {
    tree.compute(particles, field, 256);
    benchmark::DoNotOptimize(field.potential.data());
    build += tree.stats().tree_build_seconds;
  }
  state.counters["nodes_per_particle"] = tree.stats().mean_nodes_visited;
  state.counters["trees"] = double(tree.stats().trees);
  state.counters["tree_build_s"] = benchmark::Counter(build, benchmark::Counter::kAvgIterations);
  state.SetLabel(std::string(to_string(scheme)));
  swirl::parallel::set_thread_count(saved);
}

void BM_Force_double(benchmark::State& state) { force<double>(state); }
void BM_Force_float(benchmark::State& state) { force<float>(state); }

void BM_Table2(benchmark::State& state) {
  BenchSettings b;
  b.scheme = kSchemes[std::size_t(state.range(0))];
  b.n = std::size_t(state.range(1));
  b.threads = int(state.range(2));
  b.iterations = 50;
  b.opening = 0.5;
  BenchResult r;
  for (auto _ : state) {
    r = time_iterations(b);
    state.SetIterationTime(r.total);
  }
  state.counters["tree_build_s"] = r.tree_build;
  state.counters["force_s"] = r.force;
  state.counters["update_s"] = r.update;
  state.counters["nodes_per_particle"] = r.mean_nodes_visited;
  state.SetLabel(std::string(to_string(b.scheme)));
}

}  // namespace

BENCHMARK(BM_Force_double)
    ->ArgsProduct({{0, 1, 2}, {1024, 4096, 16384, 32768}, {1, 2}})
    ->ArgNames({"scheme", "n", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Force_float)
    ->ArgsProduct({{0, 1, 2}, {4096, 32768}, {1, 2}})
    ->ArgNames({"scheme", "n", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Table2)
    ->ArgsProduct({{0, 1, 2}, {1024, 2048, 4096, 8192, 16384, 32768}, {1, 2}})
    ->ArgNames({"scheme", "n", "threads"})
    ->Unit(benchmark::kSecond)
    ->UseManualTime()
    ->Iterations(1);

BENCHMARK_MAIN();
