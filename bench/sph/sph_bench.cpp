// Google Benchmark for the SPH passes on the thesis's random box (N random
// particles in a unit box, h for ~25 neighbours, float by default).
//
//   BM_Search   grid: cell keys + radix sort + reorder of every field + cell
//               table; hash: the thesis's table build + list search with density
//   BM_Density  grid density/pressure pass (args: N, threads, simd 1/0)
//   BM_Forces   grid pressure + viscosity pass (args: N, threads, simd 1/0)
//   BM_Lists    the alternative: CSR lists built from the grid, then density
//               and forces over them (compare with BM_Density + BM_Forces)
//   BM_Step     one whole SPH step (drift, search, density, forces, box, kick)
//               with the grid (strategy 0) or the hash (strategy 1)
//
// Counters: pairs_per_s (neighbour pairs, self excluded, processed per second:
// the end-to-end rate of the pass) and ns_per_particle.
// Run e.g.  sph_bench --benchmark_filter='BM_Density/1000000'
//
// The SIMD passes run the instruction set of simd::active() (the widest this
// CPU runs; core/simd_dispatch.hpp), named in each label ("simd avx512"). To
// compare the copies of one binary, run it once per set:
//   SWIRL_SIMD=sse2 sph_bench ...;  SWIRL_SIMD=avx2 ...;  SWIRL_SIMD=avx512 ...
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "swirl/core/random.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/grid_passes.hpp"
#include "swirl/sph/lattice_mass.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;
using Real = float;
constexpr std::size_t kBlock = 1024;

ParticleSet<Real> random_box(std::size_t n) {
  ParticleSet<Real> p(n);
  SplitMix64 rng(2026);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) p.position[a][i] = Real(rng.uniform());
    p.mass[i] = Real(1000.0 / double(n));
    p.id[i] = i;
  }
  return p;
}

sph::SphParameters params_for(std::size_t n, sph::NeighbourSearch search, bool simd) {
  sph::SphParameters s;
  s.smoothing_length = sph::smoothing_length_for_neighbours(25, 1.0 / double(n));
  s.rest_density = 1000;
  s.sound_speed = 1;
  s.viscosity = 0.05;
  s.neighbour_search = search;
  s.simd = simd;
  return s;
}

// The laws of the fluid (sph/laws.hpp), as SphFluid builds them.
sph::SphLaws<Real> constants(const sph::SphParameters& s) { return sph::SphLaws<Real>(s); }

// "simd <instruction set>" or "scalar".
std::string simd_label(bool simd) {
  return simd ? "simd " + std::string(simd::isa_name(simd::active())) : "scalar";
}

struct Threads {
  explicit Threads(int n) : saved(parallel::thread_count()) { parallel::set_thread_count(n); }
  ~Threads() { parallel::set_thread_count(saved); }
  int saved;
};

void report(benchmark::State& state, std::size_t n, double mean_neighbours) {
  const double pairs = mean_neighbours * double(n);
  state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["ns_per_particle"] =
      benchmark::Counter(double(n) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["neighbours"] = mean_neighbours;
}

// args: N, threads, strategy (0 grid, 1 hash)
void BM_Search(benchmark::State& state) {
  const auto n = std::size_t(state.range(0));
  Threads threads(int(state.range(1)));
  const bool grid = state.range(2) == 0;
  auto p = random_box(n);
  const auto s = params_for(n, grid ? sph::NeighbourSearch::Grid : sph::NeighbourSearch::Hash, true);
  spatial::SortedCellGrid<Real> cells;
  spatial::ParticleOrder<Real> order;  // the grid's search: the shared order's sort, then the cell index
  order.set_request(sph::SphFluid<Real>(s).order_request());
  spatial::SpatialHash<Real> hash;
  spatial::NeighbourList<Real> lists;
  const sph::Poly6<Real> w(Real(s.smoothing_length));
  double neighbours = 0;
  for (auto _ : state) {
    if (grid) {
      order.touch();  // sort every iteration, as a step without a skin does
      order.update(p, kBlock);
      cells.view(order, kBlock);
      benchmark::DoNotOptimize(p.position.x.data());
    } else {
      hash.build(p, Real(s.smoothing_length), sph::default_bucket_count(n), kBlock);
      Real* rho = p.density.data();
      hash.find_neighbours(p, spatial::DuplicateCheck::BeforeDistance, kBlock, lists, [&](std::uint32_t i, const std::uint32_t* nb, const Real* r2, std::size_t c) {
        Real sum = 0;
        for (std::size_t k = 0; k < c; ++k) sum += p.mass[nb[k]] * w(r2[k]);
        rho[i] = sum;
      });
      neighbours = double(lists.interactions()) / double(n);
    }
  }
  if (grid) {  // the pairs the grid's passes will process
    sph::SphFluid<Real> fluid(s);
    evaluate_alone(fluid, p, kBlock);
    neighbours = fluid.mean_neighbours();
  }
  report(state, n, neighbours);
  state.SetLabel(grid ? "grid" : "hash");
}

// args: N, threads, simd (1/0)
template <bool Forces>
void grid_pass(benchmark::State& state) {
  const auto n = std::size_t(state.range(0));
  Threads threads(int(state.range(1)));
  const bool simd = state.range(2) != 0;
  auto p = random_box(n);
  const auto s = params_for(n, sph::NeighbourSearch::Grid, simd);
  sph::SphFluid<Real> fluid(s);
  spatial::ParticleOrder<Real> order;  // the grid is a view of it
  evaluate_alone(fluid, p, order, kBlock);  // sorts p and fills density
  const auto k = constants(s);
  sph::GridScratch<Real> scratch;
  const KernelPath path = simd ? KernelPath::Simd : KernelPath::Scalar;
  sph::grid_density(fluid.grid(), p, k, kBlock, scratch, KernelPath::Simd);
  for (auto _ : state) {
    if constexpr (Forces) {
      sph::grid_forces(fluid.grid(), p, k, kBlock, scratch, path);
    } else {
      benchmark::DoNotOptimize(sph::grid_density(fluid.grid(), p, k, kBlock, scratch, path));
    }
    benchmark::DoNotOptimize(p.acceleration.x.data());
  }
  report(state, n, fluid.mean_neighbours());
  state.SetLabel(simd_label(simd));
}
void BM_Density(benchmark::State& state) { grid_pass<false>(state); }
void BM_Forces(benchmark::State& state) { grid_pass<true>(state); }

// args: N, threads, strategy (0 grid, 1 hash), simd (1/0)
void BM_Step(benchmark::State& state) {
  const auto n = std::size_t(state.range(0));
  Threads threads(int(state.range(1)));
  const bool grid = state.range(2) == 0;
  SimulationSettings settings;
  settings.dt = 1e-3;
  settings.block_size = kBlock;
  settings.box = boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.5};
  Simulation<Real> sim(random_box(n), settings);
  auto model = std::make_unique<sph::SphFluid<Real>>(
      params_for(n, grid ? sph::NeighbourSearch::Grid : sph::NeighbourSearch::Hash, state.range(3) != 0));
  const auto* fluid = model.get();
  sim.add_solver(std::move(model));
  sim.start();
  for (auto _ : state) sim.step();
  report(state, n, fluid->mean_neighbours());
  state.counters["bytes_per_particle"] = double(fluid->scratch_bytes()) / double(n) + 16 * sizeof(Real) + 8;
  state.SetLabel(std::string(grid ? "grid " : "hash ") + simd_label(grid && state.range(3) != 0));
}

// The alternative to computing on the fly: neighbour lists (CSR per work
// block: index j and r²) built once from the grid with AVX-512 compress-stores
// (scalar elsewhere), then density and forces over the lists. Measured here,
// not shipped: args N, threads; reports list build, density and forces
// together, to compare with BM_Density + BM_Forces.
// GCC 12 false positive on the intrinsics' undefined pass-through operands (as
// in sph/grid_passes.hpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
struct BlockLists {
  std::vector<std::uint32_t> j;
  std::vector<float> r2;
  std::vector<std::uint32_t> row_end;
};

void build_lists(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& p, Real h2,
                 std::vector<BlockLists>& lists) {
  const std::size_t n = p.size();
  lists.resize(parallel::block_count(n, kBlock));
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
  parallel::for_blocks("lists", n, kBlock, [&](std::size_t b, std::size_t e, std::size_t blk) {
    BlockLists& L = lists[blk];
    if (L.j.size() < (e - b) * 40 + 64) {  // grows below if a block needs more
      L.j.resize((e - b) * 40 + 64);
      L.r2.resize(L.j.size());
    }
    L.row_end.clear();
    std::size_t fill = 0;
    spatial::NeighbourRanges ranges{};
    std::size_t i = b;
    while (i < e) {
      const std::size_t cell_end = std::min<std::size_t>(e, grid.cell_end(static_cast<std::uint32_t>(i)));
      const int count = grid.neighbour_ranges(grid.keys()[i], ranges);
      for (; i < cell_end; ++i) {
        for (int r = 0; r < count; ++r) {
          std::size_t j = ranges[std::size_t(r)].begin;
          const std::size_t end = ranges[std::size_t(r)].end;
#if defined(__AVX512F__)
          const __m512 xi = _mm512_set1_ps(x[i]), yi = _mm512_set1_ps(y[i]), zi = _mm512_set1_ps(z[i]);
          const __m512 hh = _mm512_set1_ps(h2);
          const __m512i lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
          for (; j < end && j + 16 <= n; j += 16) {  // lanes past the range's end masked
            const __m512 dx = _mm512_sub_ps(xi, _mm512_loadu_ps(x + j)), dy = _mm512_sub_ps(yi, _mm512_loadu_ps(y + j)),
                         dz = _mm512_sub_ps(zi, _mm512_loadu_ps(z + j));
            const __m512 d2 = _mm512_fmadd_ps(dz, dz, _mm512_fmadd_ps(dy, dy, _mm512_mul_ps(dx, dx)));
            __mmask16 in = _mm512_cmp_ps_mask(d2, hh, _CMP_LT_OQ);
            if (end - j < 16) in = static_cast<__mmask16>(in & ((1u << (end - j)) - 1));
            if (j <= i && i < j + 16) in = static_cast<__mmask16>(in & ~(1u << (i - j)));
            const __m512i idx = _mm512_add_epi32(_mm512_set1_epi32(int(j)), lanes);
            if (fill + 16 > L.j.size()) {
              L.j.resize(L.j.size() * 2);
              L.r2.resize(L.j.size());
            }
            // Compress in registers, store whole: a compress straight to memory
            // is microcoded and slow on AMD Zen 4.
            _mm512_storeu_si512(L.j.data() + fill, _mm512_maskz_compress_epi32(in, idx));
            _mm512_storeu_ps(L.r2.data() + fill, _mm512_maskz_compress_ps(in, d2));
            fill += std::size_t(__builtin_popcount(in));
          }
#endif
          for (; j < end; ++j) {
            const Real d2 = spatial::distance2(x[i], y[i], z[i], x[j], y[j], z[j]);
            if (j != i && spatial::within(d2, h2)) {
              if (fill + 1 > L.j.size()) {
                L.j.resize(L.j.size() * 2);
                L.r2.resize(L.j.size());
              }
              L.j[fill] = std::uint32_t(j);
              L.r2[fill++] = d2;
            }
          }
        }
        L.row_end.push_back(std::uint32_t(fill));
      }
    }
  });
}

void BM_Lists(benchmark::State& state) {
  const auto n = std::size_t(state.range(0));
  Threads threads(int(state.range(1)));
  auto p = random_box(n);
  const auto s = params_for(n, sph::NeighbourSearch::Grid, true);
  sph::SphFluid<Real> fluid(s);
  spatial::ParticleOrder<Real> order;  // the grid is a view of it
  evaluate_alone(fluid, p, order, kBlock);
  const auto k = constants(s);
  std::vector<BlockLists> lists;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  Real *rho = p.density.data(), *pr = p.pressure.data(), *ax = p.acceleration.x.data();
  Real *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
  std::vector<Real> V(n), PV(n);
  const Real pn = k.pressure.norm, vn = k.viscosity.norm;
  double pairs = 0;
  double t_build = 0, t_density = 0, t_forces = 0;
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  for (auto _ : state) {
    auto t0 = Clock::now();
    build_lists(fluid.grid(), p, k.h2, lists);
    t_build += since(t0);
    t0 = Clock::now();
    parallel::for_blocks("density", n, kBlock, [&](std::size_t b, std::size_t e, std::size_t blk) {
      const BlockLists& L = lists[blk];
      std::size_t from = 0;
      for (std::size_t i = b; i < e; ++i) {
        Real sum = m[i] * k.h2 * k.h2 * k.h2;
        const std::size_t to = L.row_end[i - b];
#if defined(__AVX512F__)
        {  // 16 list entries at a time, m_j gathered
          __m512 acc = _mm512_setzero_ps();
          const __m512 hh = _mm512_set1_ps(k.h2);
          for (; from < to; from += 16) {
            const __mmask16 live = to - from >= 16 ? __mmask16(0xffff) : __mmask16((1u << (to - from)) - 1);
            const __m512i jj = _mm512_maskz_loadu_epi32(live, L.j.data() + from);
            const __m512 d = _mm512_sub_ps(hh, _mm512_maskz_loadu_ps(live, L.r2.data() + from));
            const __m512 mj = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), live, jj, m, 4);
            acc = _mm512_add_ps(acc, _mm512_mul_ps(mj, _mm512_mul_ps(d, _mm512_mul_ps(d, d))));
          }
          sum += _mm512_reduce_add_ps(acc);
          from = to;
        }
#endif
        for (std::size_t q = from; q < to; ++q) {
          const Real d = k.h2 - L.r2[q];
          sum += m[L.j[q]] * d * d * d;
        }
        from = to;
        rho[i] = k.density.norm * sum;
        pr[i] = k.eos.c2 * (rho[i] - k.eos.rest_density);
        V[i] = m[i] / rho[i];
        PV[i] = pr[i] * V[i];
      }
    });
    t_density += since(t0);
    t0 = Clock::now();
    parallel::for_blocks("forces", n, kBlock, [&](std::size_t b, std::size_t e, std::size_t blk) {
      const BlockLists& L = lists[blk];
      std::size_t from = 0;
      for (std::size_t i = b; i < e; ++i) {
        Real px = 0, py = 0, pz = 0, sx = 0, sy = 0, sz = 0;
        const std::size_t to = L.row_end[i - b];
#if defined(__AVX512F__)
        {  // 16 list entries at a time, every j field gathered
          __m512 apx = _mm512_setzero_ps(), apy = apx, apz = apx, asx = apx, asy = apx, asz = apx;
          const __m512 xi = _mm512_set1_ps(x[i]), yi = _mm512_set1_ps(y[i]), zi = _mm512_set1_ps(z[i]);
          const __m512 vxi = _mm512_set1_ps(vx[i]), vyi = _mm512_set1_ps(vy[i]), vzi = _mm512_set1_ps(vz[i]);
          const __m512 pri = _mm512_set1_ps(pr[i]), hb = _mm512_set1_ps(k.h), zero = _mm512_setzero_ps();
          for (; from < to; from += 16) {
            const __mmask16 live = to - from >= 16 ? __mmask16(0xffff) : __mmask16((1u << (to - from)) - 1);
            const __m512i jj = _mm512_maskz_loadu_epi32(live, L.j.data() + from);
            const __m512 r2 = _mm512_mask_loadu_ps(_mm512_set1_ps(1), live, L.r2.data() + from);
            auto gather = [&](const Real* a) { return _mm512_mask_i32gather_ps(zero, live, jj, a, 4); };
            __m512 inv = _mm512_rsqrt14_ps(r2);
            inv = _mm512_mul_ps(inv, _mm512_sub_ps(_mm512_set1_ps(1.5f), _mm512_mul_ps(_mm512_set1_ps(0.5f), _mm512_mul_ps(r2, _mm512_mul_ps(inv, inv)))));
            const __m512 qq = _mm512_max_ps(_mm512_sub_ps(hb, _mm512_mul_ps(r2, inv)), zero);
            const __m512 Vj = gather(V.data());
            const __m512 g = _mm512_maskz_mul_ps(live, _mm512_mul_ps(qq, qq), inv);
            const __m512 fp = _mm512_mul_ps(_mm512_fmadd_ps(pri, Vj, gather(PV.data())), g);
            const __m512 fv = _mm512_mul_ps(Vj, qq);
            apx = _mm512_fmadd_ps(fp, _mm512_sub_ps(xi, gather(x)), apx);
            apy = _mm512_fmadd_ps(fp, _mm512_sub_ps(yi, gather(y)), apy);
            apz = _mm512_fmadd_ps(fp, _mm512_sub_ps(zi, gather(z)), apz);
            asx = _mm512_fmadd_ps(fv, _mm512_sub_ps(gather(vx), vxi), asx);
            asy = _mm512_fmadd_ps(fv, _mm512_sub_ps(gather(vy), vyi), asy);
            asz = _mm512_fmadd_ps(fv, _mm512_sub_ps(gather(vz), vzi), asz);
          }
          px = _mm512_reduce_add_ps(apx); py = _mm512_reduce_add_ps(apy); pz = _mm512_reduce_add_ps(apz);
          sx = _mm512_reduce_add_ps(asx); sy = _mm512_reduce_add_ps(asy); sz = _mm512_reduce_add_ps(asz);
          from = to;
        }
#endif
        for (std::size_t q = from; q < to; ++q) {
          const std::uint32_t j = L.j[q];
          const Real r = std::sqrt(L.r2[q]), qq = k.h - r;
          const Real g = r > 0 ? qq * qq / r : Real(0);
          const Real fp = (pr[i] * V[j] + PV[j]) * g, fv = V[j] * qq;
          px += fp * (x[i] - x[j]);
          py += fp * (y[i] - y[j]);
          pz += fp * (z[i] - z[j]);
          sx += fv * (vx[j] - vx[i]);
          sy += fv * (vy[j] - vy[i]);
          sz += fv * (vz[j] - vz[i]);
        }
        from = to;
        ax[i] = (pn * px + vn * sx) / rho[i];
        ay[i] = (pn * py + vn * sy) / rho[i];
        az[i] = (pn * pz + vn * sz) / rho[i];
      }
    });
    t_forces += since(t0);
    pairs = 0;
    for (const auto& L : lists) pairs += L.row_end.empty() ? 0 : double(L.row_end.back());
  }
  report(state, n, pairs / double(n));
  state.counters["build_s"] = benchmark::Counter(t_build, benchmark::Counter::kAvgIterations);
  state.counters["density_s"] = benchmark::Counter(t_density, benchmark::Counter::kAvgIterations);
  state.counters["forces_s"] = benchmark::Counter(t_forces, benchmark::Counter::kAvgIterations);
  state.SetLabel("lists: build + density + forces");
}
#pragma GCC diagnostic pop

void sizes(benchmark::internal::Benchmark* b, bool strategy_arg, bool simd_arg) {
  for (long n : {10000L, 35000L, 100000L, 1000000L})
    for (long t : {1L, 2L}) {
      if (strategy_arg && simd_arg) {
        b->Args({n, t, 0, 1});
        b->Args({n, t, 0, 0});
        if (n <= 100000) b->Args({n, t, 1, 1});
      } else if (strategy_arg) {
        b->Args({n, t, 0});
        if (n <= 100000) b->Args({n, t, 1});
      } else {
        b->Args({n, t, 1});
        b->Args({n, t, 0});
      }
    }
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_Search)->Apply([](auto* b) { sizes(b, true, false); });
BENCHMARK(BM_Density)->Apply([](auto* b) { sizes(b, false, true); });
BENCHMARK(BM_Forces)->Apply([](auto* b) { sizes(b, false, true); });
BENCHMARK(BM_Step)->Apply([](auto* b) { sizes(b, true, true); });
BENCHMARK(BM_Lists)->ArgsProduct({{10000, 35000, 100000, 1000000}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
