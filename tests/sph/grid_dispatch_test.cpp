// The SPH grid passes' SIMD copies, one per instruction set this CPU runs
// (core/simd_dispatch.hpp): each against the scalar twin, each bit-identical
// for 1, 2 and 3 threads, and each really at its own width.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "swirl/core/random.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sph/grid_pass_kernels.hpp"
#include "swirl/sph/grid_passes.hpp"
#include "swirl/sph/lattice_mass.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;

constexpr std::size_t kBlock = 64;

std::vector<simd::Isa> usable_isas() {
  std::vector<simd::Isa> out;
  for (simd::Isa isa : simd::kCompiledIsas)
    if (simd::usable(isa)) out.push_back(isa);
  return out;
}

struct ThreadCount {
  explicit ThreadCount(int n) : saved(parallel::thread_count()) { parallel::set_thread_count(n); }
  ~ThreadCount() { parallel::set_thread_count(saved); }
  int saved;
};

// The thesis's random box (~25 neighbours), with random velocities so that
// viscosity acts; n not a multiple of any batch width, so that the ranges at
// the end of the array take the kernels' scalar tail.
template <class Real>
struct Box {
  static constexpr std::size_t kParticles = 2999;
  ParticleSet<Real> p;
  sph::SphParameters params;
  sph::SphFluid<Real> fluid;
  spatial::ParticleOrder<Real> order;  // the grid is a view of it
  sph::SphLaws<Real> k;

  static sph::SphParameters with_correction(sph::SphParameters s, bool corrected) {
    s.gradient_correction = corrected;
    return s;
  }
  static sph::SphParameters parameters() {
    sph::SphParameters s;
    s.smoothing_length = sph::smoothing_length_for_neighbours(25, 1.0 / double(kParticles));
    s.rest_density = 1000;
    s.sound_speed = 1;
    s.viscosity = 0.05;
    s.neighbour_search = sph::NeighbourSearch::Grid;
    s.simd = false;
    return s;
  }

  explicit Box(bool corrected = false)
      : p(kParticles), params(with_correction(parameters(), corrected)), fluid(params), k(params) {
    SplitMix64 rng(8);
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int a = 0; a < 3; ++a) {
        p.position[a][i] = Real(rng.uniform());
        p.velocity[a][i] = Real(0.2 * (rng.uniform() - 0.5));
      }
      p.mass[i] = Real(1000.0 / double(kParticles));
      p.id[i] = i;
    }
    swirl::evaluate_alone(fluid, p, order, kBlock);  // sorts p into cell order, builds the grid
    if (!fluid.used_grid()) throw std::runtime_error("test set-up: the grid was not used");
  }
};

// One evaluation of both passes: densities (and pressures) from the density
// pass; accelerations from the force pass run on `reference`'s densities and
// scratch, so that a force difference is the force pass's own.
template <class Real>
struct Result {
  std::uint64_t pairs = 0;
  std::vector<Real> density, pressure, ax, ay, az;
};

template <class Real, bool Simd>
Result<Real> evaluate(const Box<Real>& box, const Result<Real>* reference = nullptr) {
  ParticleSet<Real> p = box.p;
  sph::GridScratch<Real> scratch;
  Result<Real> r;
  r.pairs = sph::grid_density(box.fluid.grid(), p, box.k, kBlock, scratch, Simd ? KernelPath::Simd : KernelPath::Scalar);
  r.density.assign(p.density.begin(), p.density.end());
  r.pressure.assign(p.pressure.begin(), p.pressure.end());
  if (reference) {
    std::copy(reference->density.begin(), reference->density.end(), p.density.begin());
    std::copy(reference->pressure.begin(), reference->pressure.end(), p.pressure.begin());
    for (std::size_t i = 0; i < p.size(); ++i) {
      scratch.volume[i] = p.mass[i] / p.density[i];
      scratch.pressure_volume[i] = p.pressure[i] * scratch.volume[i];
    }
  }
  if (box.k.corrected) sph::grid_gradient_correction(box.fluid.grid(), p, box.k, kBlock, scratch);
  std::fill(p.acceleration.x.begin(), p.acceleration.x.end(), Real(0));
  std::fill(p.acceleration.y.begin(), p.acceleration.y.end(), Real(0));
  std::fill(p.acceleration.z.begin(), p.acceleration.z.end(), Real(0));
  sph::grid_forces(box.fluid.grid(), p, box.k, kBlock, scratch, Simd ? KernelPath::Simd : KernelPath::Scalar);
  r.ax.assign(p.acceleration.x.begin(), p.acceleration.x.end());
  r.ay.assign(p.acceleration.y.begin(), p.acceleration.y.end());
  r.az.assign(p.acceleration.z.begin(), p.acceleration.z.end());
  return r;
}

template <class Real>
bool bit_identical(const std::vector<Real>& a, const std::vector<Real>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Real)) == 0;
}

template <class Real>
class GridDispatchTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(GridDispatchTest, Precisions);

// Every copy against the scalar twin: density per particle within 1e-5
// relative (float; 1e-12 double); the force pass, on the same densities,
// per particle within 1e-5 (1e-12) of the particle's acceleration magnitude,
// floored at 1 % of the largest (where the sum is a cancellation of larger
// terms). The pair counts agree to the rounding of r² at the boundary h²
// (the wide copies contract r² into FMAs), i.e. to a few pairs in 10⁵.
// With the gradient correction (its matrices from the scalar pass, applied at
// the end of each copy's force sum) the same holds.
TYPED_TEST(GridDispatchTest, EveryCopyAgreesWithTheScalarTwin) {
  using Real = TypeParam;
  const double tol = std::is_same_v<Real, float> ? 1e-5 : 1e-12;
  for (bool corrected : {false, true}) {
    SCOPED_TRACE(corrected ? "corrected" : "uncorrected");
    const Box<Real> box(corrected);
    const Result<Real> scalar = evaluate<Real, false>(box);
    ASSERT_GT(scalar.pairs, 20 * box.p.size());
    double a_scale = 0;
    auto norm = [](const Result<Real>& r, std::size_t i) {
      return std::sqrt(double(r.ax[i]) * r.ax[i] + double(r.ay[i]) * r.ay[i] + double(r.az[i]) * r.az[i]);
    };
    for (std::size_t i = 0; i < box.p.size(); ++i) a_scale = std::max(a_scale, norm(scalar, i));
    ASSERT_GT(a_scale, 0.0);
    const auto isas = usable_isas();
    ASSERT_FALSE(isas.empty());
    for (simd::Isa isa : isas) {
      SCOPED_TRACE(std::string(simd::isa_name(isa)));
      simd::ScopedIsa scope(isa);
      const Result<Real> fast = evaluate<Real, true>(box, &scalar);
      EXPECT_NEAR(double(fast.pairs), double(scalar.pairs), 1e-4 * double(scalar.pairs));
      for (std::size_t i = 0; i < box.p.size(); ++i) {
        ASSERT_NEAR(fast.density[i], scalar.density[i], tol * double(scalar.density[i])) << "particle " << i;
        const double a_i = std::max(1e-2 * a_scale, norm(scalar, i));
        ASSERT_NEAR(fast.ax[i], scalar.ax[i], tol * a_i) << "particle " << i;
        ASSERT_NEAR(fast.ay[i], scalar.ay[i], tol * a_i) << "particle " << i;
        ASSERT_NEAR(fast.az[i], scalar.az[i], tol * a_i) << "particle " << i;
      }
    }
  }
}

// Within each copy, 1, 2 and 3 threads give the same bits.
TYPED_TEST(GridDispatchTest, EveryCopyIsBitIdenticalForOneTwoAndThreeThreads) {
  using Real = TypeParam;
  const Box<Real> box;
  for (simd::Isa isa : usable_isas()) {
    SCOPED_TRACE(std::string(simd::isa_name(isa)));
    simd::ScopedIsa scope(isa);
    std::vector<Result<Real>> runs;
    for (int threads : {1, 2, 3}) {
      ThreadCount count(threads);
      runs.push_back(evaluate<Real, true>(box));
    }
    for (std::size_t r = 1; r < runs.size(); ++r) {
      EXPECT_EQ(runs[r].pairs, runs[0].pairs) << "run " << r;
      EXPECT_TRUE(bit_identical(runs[r].density, runs[0].density)) << "run " << r;
      EXPECT_TRUE(bit_identical(runs[r].pressure, runs[0].pressure)) << "run " << r;
      EXPECT_TRUE(bit_identical(runs[r].ax, runs[0].ax)) << "run " << r;
      EXPECT_TRUE(bit_identical(runs[r].ay, runs[0].ay)) << "run " << r;
      EXPECT_TRUE(bit_identical(runs[r].az, runs[0].az)) << "run " << r;
    }
  }
}

// The dispatcher calls the copy it was told to: the copy reports its own float
// batch width, and copies of different widths sum in different orders, so
// their results differ in the last bits somewhere.
// The passes' work per particle (grid_candidates, what MPI ranks balance by)
// against the brute-force neighbours: every neighbour is a candidate, the
// particles of one cell share one count, and a range's counts are the whole
// pass's.
TEST(GridCandidates, BoundTheNeighboursAndAreOnePerCell) {
  const Box<double> box;
  const auto& grid = box.fluid.grid();
  const std::size_t n = box.p.size();
  std::vector<std::uint64_t> all(n);
  sph::grid_candidates(grid, {0, std::uint32_t(n)}, kBlock, std::span<std::uint64_t>(all));
  const auto& x = box.p.position;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t neighbours = 0;  // itself included, as the candidates
    for (std::size_t j = 0; j < n; ++j) {
      const double dx = x.x[i] - x.x[j], dy = x.y[i] - x.y[j], dz = x.z[i] - x.z[j];
      neighbours += dx * dx + dy * dy + dz * dz < box.k.h2;
    }
    ASSERT_GE(all[i], neighbours) << "particle " << i;
    ASSERT_LE(all[i], n);
    if (i > 0 && grid.keys()[i] == grid.keys()[i - 1]) {
      ASSERT_EQ(all[i], all[i - 1]) << "one cell, one count";
    }
  }
  std::vector<std::uint64_t> part(1000);
  sph::grid_candidates(grid, {500, 1500}, kBlock, std::span<std::uint64_t>(part));
  EXPECT_TRUE(std::equal(part.begin(), part.end(), all.begin() + 500));
  EXPECT_THROW(sph::grid_candidates(grid, {0, 10}, kBlock, std::span<std::uint64_t>(part)), std::invalid_argument);

  // The density pass counts the same on the way (the ranks' costs), on either kernel path, for a range too.
  for (const KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
    ParticleSet<double> p = box.p;
    sph::GridScratch<double> scratch;
    std::vector<std::uint64_t> counted(1000, 0);
    sph::grid_density(grid, p, box.k, kBlock, scratch, path, {500, 1500}, std::span<std::uint64_t>(counted));
    EXPECT_EQ(counted, part) << (path == KernelPath::Simd ? "simd" : "scalar");
    std::vector<std::uint64_t> wrong(10);
    EXPECT_THROW(sph::grid_density(grid, p, box.k, kBlock, scratch, path, {500, 1500}, std::span<std::uint64_t>(wrong)),
                 std::invalid_argument);
  }
}

TEST(GridDispatch, EachCopyRunsAtItsOwnWidth) {
  for (simd::Isa isa : usable_isas()) {
    simd::ScopedIsa scope(isa);
    if (simd::float_lanes(isa) == 0) continue;  // generic: the build's own width
    EXPECT_EQ(sph::grid_pass_float_lanes(), simd::float_lanes(isa)) << simd::isa_name(isa);
  }
  const auto isas = usable_isas();
  if (isas.size() < 2) GTEST_SKIP() << "one instruction set usable here";
  const Box<float> box;
  std::vector<Result<float>> results;
  for (simd::Isa isa : isas) {
    simd::ScopedIsa scope(isa);
    results.push_back(evaluate<float, true>(box));
  }
  for (std::size_t r = 1; r < results.size(); ++r) {
    const bool same = bit_identical(results[r].density, results[0].density) &&
                      bit_identical(results[r].ax, results[0].ax) && bit_identical(results[r].ay, results[0].ay) &&
                      bit_identical(results[r].az, results[0].az);
    EXPECT_FALSE(same) << simd::isa_name(isas[r]) << " gave " << simd::isa_name(isas[0]) << "'s bits";
  }
}

// The SPH fluid's own SIMD path follows the chosen copy too (same bits as the
// passes called directly under that copy).
TEST(GridDispatch, TheFluidUsesTheActiveCopy) {
  const Box<float> box;
  for (simd::Isa isa : usable_isas()) {
    SCOPED_TRACE(std::string(simd::isa_name(isa)));
    simd::ScopedIsa scope(isa);
    const Result<float> direct = evaluate<float, true>(box);
    auto params = box.params;
    params.simd = true;
    sph::SphFluid<float> fluid(params);
    ParticleSet<float> p = box.p;  // already in cell order: the fluid's sort keeps it
    std::fill(p.acceleration.x.begin(), p.acceleration.x.end(), 0.0f);
    std::fill(p.acceleration.y.begin(), p.acceleration.y.end(), 0.0f);
    std::fill(p.acceleration.z.begin(), p.acceleration.z.end(), 0.0f);
    swirl::evaluate_alone(fluid, p, kBlock);
    ASSERT_TRUE(fluid.used_grid());
    ASSERT_EQ(p.id, box.p.id);
    EXPECT_TRUE(bit_identical(std::vector<float>(p.density.begin(), p.density.end()), direct.density));
    EXPECT_TRUE(bit_identical(std::vector<float>(p.acceleration.x.begin(), p.acceleration.x.end()), direct.ax));
  }
}

}  // namespace
