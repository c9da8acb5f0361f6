// The solve passes over the kept pairs (sph/dfsph_pairs.hpp), scalar and
// explicit SIMD (sph/dfsph_pair_kernels.hpp, every instruction set this CPU
// runs), against their slow twins over the grid (sph/dfsph_passes.hpp), on a
// jittered block of fluid beside a wall of boundary particles, with random
// velocities and κ: the same bits (a SIMD copy that fuses multiply-adds
// otherwise than this build's scalar code: within 1e-5 of the largest
// value), the pairs found equal to the grid's, and the same bits for any
// thread count and for a pass over a sub-range (a rank's own particles among
// its ghosts).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "swirl/core/particle_kind.hpp"
#include "swirl/core/random.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/particle_order.hpp"
#include "swirl/sph/dfsph_pair_kernels.hpp"
#include "swirl/sph/dfsph_pairs.hpp"
#include "swirl/sph/dfsph_passes.hpp"

namespace {

using namespace swirl;

template <class Real>
struct Setup {
  ParticleSet<Real> p;
  std::vector<Real> kr;  // κ/ρ
  double h = 0;
  spatial::ParticleOrder<Real> order;
  spatial::SortedCellGrid<Real> grid;
  std::size_t kind_field = 0;
  const std::int32_t* kind() const { return p.int_field(kind_field).data(); }
};

// A 12 × 12 × 10 block of fluid at spacing s, jittered by up to s/4, on a
// floor of boundary particles (one layer at z = 0); h = 2 s.
template <class Real>
void make(Setup<Real>& s) {
  const double sp = 0.01;
  s.h = 2 * sp;
  s.kind_field = s.p.add_int_field(std::string(kKindField));
  SplitMix64 rng(7);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
  std::size_t n = 0;
  auto add = [&](double x, double y, double z, bool boundary) {
    s.p.resize(n + 1);
    s.p.position.set(n, Vec3d{x, y, z}.cast<Real>());
    s.p.velocity.set(n, boundary ? Vec3<Real>{} : Vec3d{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)}.cast<Real>());
    s.p.mass[n] = Real(boundary ? 0.6 : 1.0);
    s.p.id[n] = n;
    s.p.int_field(s.kind_field)[n] = boundary ? 1 : 0;
    ++n;
  };
  for (int i = -2; i < 14; ++i)
    for (int j = -2; j < 14; ++j) add(i * sp, j * sp, 0, true);
  for (int k = 1; k <= 10; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i)
        add((i + uniform(-0.25, 0.25)) * sp, (j + uniform(-0.25, 0.25)) * sp, (k + uniform(-0.25, 0.25)) * sp,
            false);
  spatial::OrderRequest request;
  request.sorted = true;
  request.cell_length = s.h;
  s.order.set_request(request);
  s.order.update(s.p, 64);
  ASSERT_TRUE(s.grid.view(s.order, 64));
  s.kr.resize(s.p.size());
  for (std::size_t i = 0; i < s.p.size(); ++i) s.kr[i] = is_boundary(s.kind()[i]) ? Real(0) : Real(uniform(0, 2e-3));
}

template <class F>
auto with_threads(int n, F&& f) {
  const int saved = parallel::thread_count();
  parallel::set_thread_count(n);
  auto result = f();
  parallel::set_thread_count(saved);
  return result;
}

template <class Real>
class DfsphPairsTest : public ::testing::Test {};
using Reals = ::testing::Types<float, double>;
TYPED_TEST_SUITE(DfsphPairsTest, Reals);

TYPED_TEST(DfsphPairsTest, SolvePassesGiveTheGridPassesBits) {
  using Real = TypeParam;
  Setup<Real> s;
  make(s);
  const std::size_t n = s.p.size(), bs = 64;
  const sph::DfsphKernel<Real> kernel(sph::SphKernel::CubicSpline, Real(s.h));
  std::vector<Real> alpha(n), alpha_kept(n);
  const std::uint64_t found = sph::dfsph_density_and_factor(s.grid, s.p, kernel, bs, alpha.data(), Real(1e30), s.kind(), Real(1000));
  sph::DfsphPairs<Real> pairs;
  const std::uint64_t found_kept = sph::dfsph_density_and_factor(s.grid, s.p, kernel, bs, alpha_kept.data(), Real(1e30), s.kind(),
                                                                 Real(1000), sph::detail::kAllParticles, &pairs);
  // Keeping the pairs changes nothing the pass computes, and keeps every pair it found.
  EXPECT_EQ(found, found_kept);
  EXPECT_EQ(alpha, alpha_kept);
  EXPECT_EQ(pairs.pairs(), found);  // boundary particles' own pairs are neither counted nor kept
  ASSERT_GT(found, 30 * 1000u);

  const IndexRange all{0, static_cast<std::uint32_t>(n)};
  std::vector<Real> slow(n);
  sph::dfsph_density_change(s.grid, s.p, kernel, bs, slow.data(), s.kind());
  double largest = 0, largest_v = 0;
  for (std::size_t i = 0; i < n; ++i) largest = std::max(largest, std::abs(double(slow[i])));
  ASSERT_GT(largest, 1.0);  // a velocity field that changes the density
  ParticleSet<Real> slow_p = s.p;
  sph::dfsph_pressure_velocity(s.grid, slow_p, kernel, bs, s.kr.data(), Real(1e-3), s.kind());
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) largest_v = std::max(largest_v, std::abs(double(slow_p.velocity[a][i])));

  // The scalar loops, then the SIMD copies (float; double runs the scalar loops on either path).
  struct Case {
    KernelPath path;
    simd::Isa isa;
  };
  std::vector<Case> cases{{KernelPath::Scalar, simd::active()}};
  for (simd::Isa isa : simd::kCompiledIsas)
    if (simd::cpu_supports(isa)) cases.push_back({KernelPath::Simd, isa});
#if defined(__FMA__)
  constexpr bool kScalarFuses = true;
#else
  constexpr bool kScalarFuses = false;
#endif
  for (const Case& c : cases) {
    const simd::ScopedIsa scoped(c.isa);
    const bool exact = c.path == KernelPath::Scalar || !std::is_same_v<Real, float> ||
                       sph::dfsph_pairs_simd_fuses() == kScalarFuses;
    SCOPED_TRACE(std::string(c.path == KernelPath::Scalar ? "scalar" : "simd ") + std::string(simd::isa_name(c.isa)));
    std::vector<Real> fast(n, Real(-1));
    sph::dfsph_density_change(pairs, s.p, bs, fast.data(), s.kind(), all, c.path);
    for (std::size_t i = 0; i < n; ++i) {
      if (exact)
        EXPECT_EQ(fast[i], slow[i]) << i;  // the same expressions on the same operands: the same bits
      else
        EXPECT_NEAR(fast[i], slow[i], 1e-5 * largest) << i;
    }
    ParticleSet<Real> q = s.p;
    sph::dfsph_pressure_velocity(pairs, q, bs, s.kr.data(), Real(1e-3), s.kind(), all, c.path);
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) {
        if (exact)
          EXPECT_EQ(q.velocity[a][i], slow_p.velocity[a][i]) << i << " " << a;
        else
          EXPECT_NEAR(q.velocity[a][i], slow_p.velocity[a][i], 1e-5 * largest_v) << i << " " << a;
      }
  }
}

TYPED_TEST(DfsphPairsTest, AnyThreadCountAndASubRangeGiveTheSameBits) {
  using Real = TypeParam;
  Setup<Real> s;
  make(s);
  const std::size_t n = s.p.size(), bs = 64;
  const sph::DfsphKernel<Real> kernel(sph::SphKernel::CubicSpline, Real(s.h));
  std::vector<Real> alpha(n);
  const IndexRange all{0, static_cast<std::uint32_t>(n)};
  const IndexRange part{100, static_cast<std::uint32_t>(n - 50)};
  for (const KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
    SCOPED_TRACE(path == KernelPath::Scalar ? "scalar" : "simd");
    auto run = [&](IndexRange range, int iterations) {
      sph::DfsphPairs<Real> pairs;
      sph::dfsph_density_and_factor(s.grid, s.p, kernel, bs, alpha.data(), Real(1e30), s.kind(), Real(1000), range,
                                    &pairs);
      std::vector<Real> change(n, Real(-1));
      ParticleSet<Real> q = s.p;
      // Iterations on the same pairs: the packed positions kept, the velocities packed again.
      for (int it = 0; it < iterations; ++it) {
        sph::dfsph_density_change(pairs, q, bs, change.data(), s.kind(), range, path);
        sph::dfsph_pressure_velocity(pairs, q, bs, s.kr.data(), Real(1e-3), s.kind(), range, path);
      }
      std::vector<Real> v(q.velocity.x.begin(), q.velocity.x.end());
      v.insert(v.end(), q.velocity.z.begin(), q.velocity.z.end());
      v.insert(v.end(), change.begin(), change.end());
      return v;
    };
    const auto one = with_threads(1, [&] { return run(all, 2); });
    const auto two = with_threads(2, [&] { return run(all, 2); });
    const auto three = with_threads(3, [&] { return run(all, 2); });
    EXPECT_EQ(one, two);
    EXPECT_EQ(one, three);
    // A sub-range starting off a block boundary: its particles' bits are those of the whole pass
    // (one iteration: in a second, the particles outside the range would have moved in one run only).
    const auto whole = run(all, 1), sub = run(part, 1);
    for (std::size_t i = part.begin; i < part.end; ++i)
      for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(sub[c * n + i], whole[c * n + i]) << i << " " << c;
  }
  // A pass over pairs kept for another range is refused.
  sph::DfsphPairs<Real> pairs;
  sph::dfsph_density_and_factor(s.grid, s.p, kernel, bs, alpha.data(), Real(1e30), s.kind(), Real(1000), part, &pairs);
  std::vector<Real> change(n);
  for (const KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
    EXPECT_THROW(sph::dfsph_density_change(pairs, s.p, bs, change.data(), s.kind(), all, path), std::logic_error);
    EXPECT_THROW(sph::dfsph_density_change(pairs, s.p, 32, change.data(), s.kind(), part, path), std::logic_error);
  }
}

}  // namespace
