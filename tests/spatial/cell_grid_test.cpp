// The sorted cell grid against its slow twin (brute_force_pairs), and the
// parallel reorder that goes with it.
#include "swirl/spatial/cell_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <cstdint>
#include <utility>
#include <vector>

#include "swirl/core/random.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/brute_force.hpp"
#include "swirl/spatial/distance.hpp"
#include "swirl/spatial/reorder_particles.hpp"

namespace {

using namespace swirl;
using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

template <class Real>
ParticleSet<Real> random_particles(std::size_t n, double side, std::uint64_t seed) {
  ParticleSet<Real> p(n);
  SplitMix64 rng(seed);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) p.position[a][i] = Real(side * rng.uniform());
    p.mass[i] = Real(1 + i);
    p.id[i] = i;
  }
  return p;
}

// Sorts and reorders a copy of p with the grid, then lists every pair the
// grid's ranges give, as (id_i, id_j) sorted: comparable to brute force on p
// when p's ids are its indices.
template <class Real>
Pairs grid_pairs(const ParticleSet<Real>& p, Real h, std::size_t block_size, bool* dense = nullptr) {
  spatial::SortedCellGrid<Real> grid;
  EXPECT_TRUE(grid.sort(p, double(h), block_size));
  ParticleSet<Real> q = p;
  spatial::ParticleReorder<Real> reorder;
  reorder.apply(q, grid.order(), block_size);
  grid.index(block_size);
  if (dense) *dense = grid.dense();
  Pairs pairs;
  const Real h2 = h * h;
  spatial::NeighbourRanges ranges{};
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(grid.keys()[i - 1], grid.keys()[i]);
    }
    const int count = grid.neighbour_ranges(grid.keys()[i], ranges);
    for (int r = 0; r < count; ++r)
      for (std::uint32_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j)
        if (j != i && spatial::within(spatial::distance2(q.position.x[i], q.position.y[i], q.position.z[i],
                                                         q.position.x[j], q.position.y[j], q.position.z[j]),
                                      h2))
          pairs.emplace_back(static_cast<std::uint32_t>(q.id[i]), static_cast<std::uint32_t>(q.id[j]));
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

template <class Real>
class CellGridTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CellGridTest, Precisions);

TYPED_TEST(CellGridTest, FindsExactlyTheBruteForcePairsInARandomBox) {
  using Real = TypeParam;
  const auto p = random_particles<Real>(1500, 1.0, 3);
  for (Real h : {Real(0.02), Real(0.09), Real(0.3), Real(2.0)}) {
    bool dense = false;
    const Pairs got = grid_pairs(p, h, 64, &dense);
    EXPECT_EQ(dense, h > Real(0.05));  // 50³ cells for 1500 particles is sparse
    EXPECT_EQ(got, spatial::brute_force_pairs(p, h)) << "h = " << h;
  }
}

// A lattice of spacing h/2 starting at 0: many pairs at exactly h (not
// neighbours) and exactly on cell faces, plus particles on the walls of the box
// [0, 1] and in its corners.
TYPED_TEST(CellGridTest, FindsExactlyTheBruteForcePairsOnCellFacesAndWalls) {
  using Real = TypeParam;
  const Real h = Real(0.125);
  ParticleSet<Real> p;
  std::size_t n = 0;
  auto add = [&](double x, double y, double z) {
    p.resize(n + 1);
    p.position.set(n, Vec3d{x, y, z}.cast<Real>());
    p.id[n] = n;
    ++n;
  };
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; j += 2)
      for (int k = 0; k <= 16; k += 4) add(i * 0.0625, j * 0.0625, k * 0.0625);
  SplitMix64 rng(5);
  for (int c = 0; c < 300; ++c) {  // random points on the six walls
    Vec3d x{rng.uniform(), rng.uniform(), rng.uniform()};
    x[c % 3] = (c / 3) % 2 ? 1.0 : 0.0;
    add(x.x, x.y, x.z);
  }
  const Pairs expected = spatial::brute_force_pairs(p, h);
  ASSERT_GT(expected.size(), 1000u);
  EXPECT_EQ(grid_pairs(p, h, 50), expected);
}

// One far particle makes the box too big for a dense table: the sparse lookup
// (binary search in the sorted keys) must find the same pairs.
TYPED_TEST(CellGridTest, SparseLookupFindsTheSamePairs) {
  using Real = TypeParam;
  auto p = random_particles<Real>(1200, 1.0, 9);
  p.position.x[7] = Real(5000);  // 5000/0.05 = 10^5 cells along x
  const Real h = Real(0.05);
  bool dense = true;
  const Pairs got = grid_pairs(p, h, 64, &dense);
  EXPECT_FALSE(dense);
  EXPECT_EQ(got, spatial::brute_force_pairs(p, h));
}

TYPED_TEST(CellGridTest, RefusesParticlesSpreadOverMoreThanTheKeyRange) {
  using Real = TypeParam;
  auto p = random_particles<Real>(100, 1.0, 1);
  p.position.y[3] = Real(1e6);  // 10^6 / 0.01 = 10^8 cells > 2^21
  spatial::SortedCellGrid<Real> grid;
  EXPECT_FALSE(grid.sort(p, 0.01, 16));
  EXPECT_TRUE(grid.sort(p, 1.0, 16));
}

TYPED_TEST(CellGridTest, RejectsNonFinitePositions) {
  using Real = TypeParam;
  auto p = random_particles<Real>(100, 1.0, 1);
  p.position.z[42] = std::numeric_limits<Real>::quiet_NaN();
  spatial::SortedCellGrid<Real> grid;
  EXPECT_THROW(grid.sort(p, 0.1, 16), std::runtime_error);
}

TYPED_TEST(CellGridTest, ReorderMovesEveryFieldAndKeepsIds) {
  using Real = TypeParam;
  auto p = random_particles<Real>(1000, 1.0, 17);
  const std::size_t extra = p.add_field("extra", 3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.velocity.y[i] = Real(2 * i);
    p.acceleration_prev.z[i] = Real(3 * i);
    p.density[i] = Real(4 * i);
    p.pressure[i] = Real(5 * i);
    p.extra(extra, 2)[i] = Real(6 * i);
    p.id[i] = 1000000 + i;
  }
  spatial::SortedCellGrid<Real> grid;
  ASSERT_TRUE(grid.sort(p, 0.1, 32));
  auto q = p;
  spatial::ParticleReorder<Real> reorder;
  reorder.apply(q, grid.order(), 32);
  std::vector<bool> seen(p.size(), false);
  for (std::size_t k = 0; k < q.size(); ++k) {
    const std::size_t i = q.id[k] - 1000000;
    ASSERT_LT(i, p.size());
    EXPECT_FALSE(seen[i]);
    seen[i] = true;
    EXPECT_EQ(grid.order()[k], i);
    EXPECT_EQ(q.position.x[k], p.position.x[i]);
    EXPECT_EQ(q.velocity.y[k], p.velocity.y[i]);
    EXPECT_EQ(q.acceleration_prev.z[k], p.acceleration_prev.z[i]);
    EXPECT_EQ(q.mass[k], p.mass[i]);
    EXPECT_EQ(q.density[k], p.density[i]);
    EXPECT_EQ(q.pressure[k], p.pressure[i]);
    EXPECT_EQ(q.extra(extra, 2)[k], p.extra(extra, 2)[i]);
  }
}

TYPED_TEST(CellGridTest, OrderIsTheSameForOneTwoAndThreeThreads) {
  using Real = TypeParam;
  const auto p = random_particles<Real>(40000, 1.0, 23);
  std::vector<std::uint32_t> first;
  const int before = parallel::thread_count();
  for (int threads : {1, 2, 3}) {
    parallel::set_thread_count(threads);
    spatial::SortedCellGrid<Real> grid;
    ASSERT_TRUE(grid.sort(p, 0.03, 256));
    std::vector<std::uint32_t> order(grid.order().begin(), grid.order().end());
    if (first.empty())
      first = order;
    else
      EXPECT_EQ(order, first) << threads << " threads";
  }
  parallel::set_thread_count(before);
}

}  // namespace
