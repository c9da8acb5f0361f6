// Google Benchmark for the gravity solver (Demiroz et al. 2011, section 5).
//
//   BM_Force   one force evaluation (tree build + walks) of a Plummer sphere,
//              per scheme, N and thread count, with the nodes visited per particle;
//   BM_Table2  the paper's experiment: 50 iterations of force + leapfrog update,
//              λ = 0.5, N = 1024 … 32768, reported as the total time (compare
//              Table 2) with the phases of Table 1 as counters (seconds);
//   BM_Kernel_float, BM_Kernel_double
//              the group walk's interaction kernels (interaction_kernels.hpp):
//              kernel 0 particle–particle, 1 monopole, 2 quadrupole; path 0 the
//              scalar reference, 1 sse2, 2 avx2, 3 avx512 (the SIMD copies, a
//              path this CPU cannot run is skipped); one group of `targets`
//              particles against `sources` sources, all in L1. Counters, per
//              second of CPU time: interactions, GFLOP/s from the flop counts
//              of interaction_kernels.hpp, and of_peak, the fraction of the
//              core's peak assumed below;
//   BM_PeakFma the core's measured FMA peak (12 independent chains of 512-bit,
//              or 256-bit, float FMAs), the basis of that assumption.
//
// Run e.g.  gravity_bench --benchmark_filter=Table2
//           gravity_bench --benchmark_filter=Kernel --benchmark_repetitions=2
#include <benchmark/benchmark.h>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <array>
#include <random>
#include <string>
#include <vector>

#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/bench.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/gravity/interaction_kernels.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace {

using namespace swirl::gravity;
using swirl::KernelPath;
constexpr std::array<Scheme, 3> kSchemes{Scheme::Subdomain, Scheme::Subtree, Scheme::Global};

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

// The core's peak assumed for of_peak, in GFLOP/s of float: AMD EPYC Zen 5
// (lscpu: family 26) with full-width AVX-512, 2 FMA pipes × 16 floats × 2
// flops × 4.4 GHz (the clock a chain of dependent adds shows in CPU time:
// 4.07–4.42 GHz on 2026-11-22; BM_PeakFma/bits:512 measures 261–282 GFLOP/s).
// Double: half. For every path, scalar and SSE2 included, of_peak is against
// this one core peak.
constexpr double kAssumedPeakFloatGflops = 2 * 16 * 2 * 4.4;

constexpr std::array<const char*, 3> kKernelNames{"particle", "monopole", "quadrupole"};
constexpr std::array<swirl::simd::Isa, 3> kKernelIsas{swirl::simd::Isa::Sse2, swirl::simd::Isa::Avx2,
                                                      swirl::simd::Isa::Avx512};

template <class Real>
void kernel(benchmark::State& state) {
  const auto kind = std::size_t(state.range(0));
  const auto path_index = std::size_t(state.range(1));
  const auto n_targets = std::size_t(state.range(2));
  const auto n_sources = std::size_t(state.range(3));
  const KernelPath path = path_index == 0 ? KernelPath::Scalar : KernelPath::Simd;
  std::string label = std::string(kKernelNames[kind]) + " ";
  swirl::simd::Isa isa = swirl::simd::active();
  if (path_index > 0) {
    isa = kKernelIsas[path_index - 1];
    if (!swirl::simd::usable(isa)) {
      state.SkipWithError((std::string(swirl::simd::isa_name(isa)) + " is not usable on this CPU").c_str());
      return;
    }
    label += std::string(swirl::simd::isa_name(isa));
  } else {
    label += "scalar";
  }
  swirl::simd::ScopedIsa scope(isa);
  // Sources in a cube of side 2 around the targets (side 0.2): a far cell's
  // list and a near leaf's alike; the values do not change the work.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  auto fill = [&](std::size_t n, double scale) {
    std::vector<Real> v(n);
    for (Real& x : v) x = Real(scale * u(rng));
    return v;
  };
  const auto sx = fill(n_sources, 1), sy = fill(n_sources, 1), sz = fill(n_sources, 1), sm = fill(n_sources, 0.5);
  std::vector<Real> mass(n_sources);
  for (std::size_t j = 0; j < n_sources; ++j) mass[j] = Real(1) + sm[j];
  const auto qxx = fill(n_sources, 1e-3), qxy = fill(n_sources, 1e-3), qxz = fill(n_sources, 1e-3),
             qyy = fill(n_sources, 1e-3), qyz = fill(n_sources, 1e-3);
  const auto tx = fill(n_targets, 0.1), ty = fill(n_targets, 0.1), tz = fill(n_targets, 0.1);
  std::vector<Real> ax(n_targets), ay(n_targets), az(n_targets), phi(n_targets);
  const SourceParticles<Real> particles{sx.data(), sy.data(), sz.data(), mass.data(), n_sources};
  const SourceCells<Real> cells{sx.data(),  sy.data(),  sz.data(),  mass.data(), qxx.data(),
                                qxy.data(), qxz.data(), qyy.data(), qyz.data(),  n_sources};
  const Targets<Real> targets{tx.data(), ty.data(), tz.data(), ax.data(), ay.data(), az.data(), phi.data(), n_targets};
  const Real eps2 = Real(1e-4);
  for (auto _ : state) {
    if (kind == 0)
      add_particle_field(particles, targets, eps2, path);
    else
      add_cell_field(cells, targets, eps2, kind == 2, path);
    benchmark::DoNotOptimize(ax.data());
    benchmark::ClobberMemory();
  }
  const int flops = kind == 0 ? kParticleFlops : kind == 1 ? kMonopoleFlops : kQuadrupoleFlops;
  const double interactions = double(state.iterations()) * double(n_targets * n_sources);
  const double peak = kAssumedPeakFloatGflops * 1e9 * (sizeof(Real) == 4 ? 1 : 0.5);
  state.counters["interactions"] = benchmark::Counter(interactions, benchmark::Counter::kIsRate);
  state.counters["GFLOPs"] = benchmark::Counter(interactions * flops * 1e-9, benchmark::Counter::kIsRate);
  state.counters["of_peak"] = benchmark::Counter(interactions * flops / peak, benchmark::Counter::kIsRate);
  state.SetLabel(label);
}

// 12 independent chains of n float FMAs each (latency × pipes ≤ 12), in the
// given width; returns a value that depends on every chain.
#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx512f,fma"))) float fma_chains_512(long n) {
  __m512 a0 = _mm512_set1_ps(1.0f), a1 = _mm512_set1_ps(1.001f), a2 = _mm512_set1_ps(1.002f),
         a3 = _mm512_set1_ps(1.003f), a4 = _mm512_set1_ps(1.004f), a5 = _mm512_set1_ps(1.005f),
         a6 = _mm512_set1_ps(1.006f), a7 = _mm512_set1_ps(1.007f), a8 = _mm512_set1_ps(1.008f),
         a9 = _mm512_set1_ps(1.009f), a10 = _mm512_set1_ps(1.01f), a11 = _mm512_set1_ps(1.011f);
  const __m512 b = _mm512_set1_ps(0.999999f), c = _mm512_set1_ps(1e-7f);
  for (long i = 0; i < n; ++i) {
    a0 = _mm512_fmadd_ps(a0, b, c), a1 = _mm512_fmadd_ps(a1, b, c), a2 = _mm512_fmadd_ps(a2, b, c);
    a3 = _mm512_fmadd_ps(a3, b, c), a4 = _mm512_fmadd_ps(a4, b, c), a5 = _mm512_fmadd_ps(a5, b, c);
    a6 = _mm512_fmadd_ps(a6, b, c), a7 = _mm512_fmadd_ps(a7, b, c), a8 = _mm512_fmadd_ps(a8, b, c);
    a9 = _mm512_fmadd_ps(a9, b, c), a10 = _mm512_fmadd_ps(a10, b, c), a11 = _mm512_fmadd_ps(a11, b, c);
  }
  const __m512 s = _mm512_add_ps(_mm512_add_ps(_mm512_add_ps(a0, a1), _mm512_add_ps(a2, a3)),
                                 _mm512_add_ps(_mm512_add_ps(_mm512_add_ps(a4, a5), _mm512_add_ps(a6, a7)),
                                               _mm512_add_ps(_mm512_add_ps(a8, a9), _mm512_add_ps(a10, a11))));
  alignas(64) float v[16];
  _mm512_store_ps(v, s);
  float sum = 0;
  for (float x : v) sum += x;
  return sum;
}
__attribute__((target("avx2,fma"))) float fma_chains_256(long n) {
  __m256 a0 = _mm256_set1_ps(1.0f), a1 = _mm256_set1_ps(1.001f), a2 = _mm256_set1_ps(1.002f),
         a3 = _mm256_set1_ps(1.003f), a4 = _mm256_set1_ps(1.004f), a5 = _mm256_set1_ps(1.005f),
         a6 = _mm256_set1_ps(1.006f), a7 = _mm256_set1_ps(1.007f), a8 = _mm256_set1_ps(1.008f),
         a9 = _mm256_set1_ps(1.009f), a10 = _mm256_set1_ps(1.01f), a11 = _mm256_set1_ps(1.011f);
  const __m256 b = _mm256_set1_ps(0.999999f), c = _mm256_set1_ps(1e-7f);
  for (long i = 0; i < n; ++i) {
    a0 = _mm256_fmadd_ps(a0, b, c), a1 = _mm256_fmadd_ps(a1, b, c), a2 = _mm256_fmadd_ps(a2, b, c);
    a3 = _mm256_fmadd_ps(a3, b, c), a4 = _mm256_fmadd_ps(a4, b, c), a5 = _mm256_fmadd_ps(a5, b, c);
    a6 = _mm256_fmadd_ps(a6, b, c), a7 = _mm256_fmadd_ps(a7, b, c), a8 = _mm256_fmadd_ps(a8, b, c);
    a9 = _mm256_fmadd_ps(a9, b, c), a10 = _mm256_fmadd_ps(a10, b, c), a11 = _mm256_fmadd_ps(a11, b, c);
  }
  const __m256 s = _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(a0, a1), _mm256_add_ps(a2, a3)),
                                 _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(a4, a5), _mm256_add_ps(a6, a7)),
                                               _mm256_add_ps(_mm256_add_ps(a8, a9), _mm256_add_ps(a10, a11))));
  alignas(32) float v[8];
  _mm256_store_ps(v, s);
  float sum = 0;
  for (float x : v) sum += x;
  return sum;
}
#endif

// The FMA peak in float GFLOP/s: range(0) = 512 or 256 bits.
void BM_PeakFma(benchmark::State& state) {
#if defined(__x86_64__) && defined(__GNUC__)
  const bool wide = state.range(0) == 512;
  if (!swirl::simd::cpu_supports(wide ? swirl::simd::Isa::Avx512 : swirl::simd::Isa::Avx2)) {
    state.SkipWithError("this CPU has no such FMA");
    return;
  }
  const long n = 1 << 20;
  volatile long count = n;  // read every iteration: the (pure) call cannot be hoisted out of the loop
  for (auto _ : state) benchmark::DoNotOptimize(wide ? fma_chains_512(count) : fma_chains_256(count));
  const double flops = double(state.iterations()) * double(n) * 12 * (wide ? 16 : 8) * 2;
  state.counters["GFLOPs"] = benchmark::Counter(flops * 1e-9, benchmark::Counter::kIsRate);
#else
  state.SkipWithError("x86-64 only");
#endif
}

void BM_Kernel_float(benchmark::State& state) { kernel<float>(state); }
void BM_Kernel_double(benchmark::State& state) { kernel<double>(state); }

}  // namespace

BENCHMARK(BM_PeakFma)->Arg(512)->Arg(256)->ArgName("bits");
BENCHMARK(BM_Kernel_float)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2, 3}, {16, 40, 64}, {512}})
    ->ArgNames({"kernel", "path", "targets", "sources"});
BENCHMARK(BM_Kernel_double)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2, 3}, {16, 40, 64}, {512}})
    ->ArgNames({"kernel", "path", "targets", "sources"});

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
