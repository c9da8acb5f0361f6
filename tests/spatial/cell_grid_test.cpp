// The sorted cell grid, a view of the shared particle order, against its slow
// twin (brute_force_pairs); the order itself (keys, sort, reorder, skin).
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
#include "swirl/spatial/particle_order.hpp"

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

// Every pair the grid's ranges give for the particles q (in the grid's memory
// order, possibly moved since the sort), as (id_i, id_j) sorted. Also checks
// that the ranges are in increasing memory order and do not overlap.
template <class Real>
Pairs pairs_of(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& q, Real h) {
  Pairs pairs;
  const Real h2 = h * h;
  spatial::NeighbourRanges ranges{};
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(grid.keys()[i - 1], grid.keys()[i]);
    }
    const int count = grid.neighbour_ranges(grid.keys()[i], ranges);
    EXPECT_LE(count, grid.cell_order() == spatial::CellOrder::Rows ? 9 : 27);
    // Morton merges ranges that touch; rows keep one range per row.
    const bool merged = grid.cell_order() == spatial::CellOrder::Morton;
    for (int r = 1; r < count; ++r)
      EXPECT_LT(ranges[static_cast<std::size_t>(r - 1)].end, ranges[static_cast<std::size_t>(r)].begin + (merged ? 0 : 1));
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

// Brings p into the order a grid of support h and skin asks for (sorting and
// reordering p in place when the order needs it) and indexes the grid on it.
template <class Real>
bool order_and_view(spatial::ParticleOrder<Real>& order, spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                    double h, std::size_t block_size, spatial::CellOrder curve, double skin = 0) {
  order.set_request({true, spatial::SortedCellGrid<Real>::cell_length_for(h, skin), skin / 2, curve});
  order.update(p, block_size);
  return grid.view(order, block_size);
}

// Sorts a copy of p into the grid's order, then lists every pair the grid's
// ranges give: comparable to brute force on p when p's ids are its indices.
template <class Real>
Pairs grid_pairs(const ParticleSet<Real>& p, Real h, std::size_t block_size, bool* dense = nullptr,
                 spatial::CellOrder curve = spatial::CellOrder::Rows) {
  spatial::ParticleOrder<Real> order;
  spatial::SortedCellGrid<Real> grid;
  ParticleSet<Real> q = p;
  EXPECT_TRUE(order_and_view(order, grid, q, double(h), block_size, curve));
  if (dense) *dense = grid.dense();
  return pairs_of(grid, q, h);
}

// The ids of p in memory order.
template <class Real>
std::vector<std::uint64_t> ids_of(const ParticleSet<Real>& p) {
  return {p.id.begin(), p.id.end()};
}

constexpr spatial::CellOrder kOrders[] = {spatial::CellOrder::Rows, spatial::CellOrder::Morton};
const char* order_name(spatial::CellOrder o) { return o == spatial::CellOrder::Rows ? "rows" : "morton"; }

template <class Real>
class CellGridTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CellGridTest, Precisions);

TYPED_TEST(CellGridTest, FindsExactlyTheBruteForcePairsInARandomBox) {
  using Real = TypeParam;
  const auto p = random_particles<Real>(1500, 1.0, 3);
  for (Real h : {Real(0.02), Real(0.09), Real(0.3), Real(2.0)}) {
    const Pairs expected = spatial::brute_force_pairs(p, h);
    for (auto order : kOrders) {
      bool dense = false;
      const Pairs got = grid_pairs(p, h, 64, &dense, order);
      // 50³ cells for 1500 particles is sparse (Morton: 2^(3·4) keys for 11³ cells is dense)
      EXPECT_EQ(dense, h > Real(0.05)) << order_name(order);
      EXPECT_EQ(got, expected) << "h = " << h << ", " << order_name(order);
    }
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
  for (auto order : kOrders) EXPECT_EQ(grid_pairs(p, h, 50, nullptr, order), expected) << order_name(order);
}

// One far particle makes the box too big for a dense table: the sparse lookup
// (the hash table of occupied cells) must find the same pairs.
TYPED_TEST(CellGridTest, SparseLookupFindsTheSamePairs) {
  using Real = TypeParam;
  auto p = random_particles<Real>(1200, 1.0, 9);
  p.position.x[7] = Real(5000);  // 5000/0.05 = 10^5 cells along x
  const Real h = Real(0.05);
  const Pairs expected = spatial::brute_force_pairs(p, h);
  for (auto order : kOrders) {
    bool dense = true;
    const Pairs got = grid_pairs(p, h, 64, &dense, order);
    EXPECT_FALSE(dense);
    EXPECT_EQ(got, expected) << order_name(order);
  }
}

// The hash table of occupied cells against the dense table on the same
// particles: the same ranges for every cell of the box (occupied or not), with
// both orders, a dense and a sparse spread, and 1, 2 and 3 threads.
TYPED_TEST(CellGridTest, HashedTableGivesTheDenseTablesRanges) {
  using Real = TypeParam;
  const int before = parallel::thread_count();
  for (double far : {0.0, 6.0})  // 6: one particle 120 cells away along x
    for (auto curve : kOrders) {
      auto p = random_particles<Real>(3000, 1.0, 51);
      if (far > 0) p.position.x[11] = Real(far);
      const double h = 0.05;
      spatial::ParticleOrder<Real> order;
      spatial::SortedCellGrid<Real> dense;
      dense.set_table(spatial::CellTable::Dense);
      auto q = p;
      ASSERT_TRUE(order_and_view(order, dense, q, h, 128, curve));
      ASSERT_TRUE(dense.dense());
      const auto dims = dense.dims();
      for (int threads : {1, 2, 3}) {
        parallel::set_thread_count(threads);
        spatial::ParticleOrder<Real> order2;
        spatial::SortedCellGrid<Real> hashed;
        hashed.set_table(spatial::CellTable::Hashed);
        auto r = p;
        ASSERT_TRUE(order_and_view(order2, hashed, r, h, 128, curve));
        ASSERT_FALSE(hashed.dense());
        ASSERT_EQ(ids_of(r), ids_of(q));
        spatial::NeighbourRanges a{}, b{};
        std::size_t compared = 0;
        // Every cell of the box (an empty cell's neighbours may not be).
        for (std::uint64_t z = 0; z < dims[2]; ++z)
          for (std::uint64_t y = 0; y < dims[1]; ++y)
            for (std::uint64_t x = 0; x < dims[0]; x += (far > 0 ? 3 : 1)) {
              const std::uint64_t key = curve == spatial::CellOrder::Rows ? (z * dims[1] + y) * dims[0] + x
                                                                          : spatial::morton_key(x, y, z);
              const int na = dense.neighbour_ranges(key, a), nb = hashed.neighbour_ranges(key, b);
              ASSERT_EQ(na, nb) << "cell " << x << " " << y << " " << z;
              for (int k = 0; k < na; ++k) {
                ASSERT_EQ(a[static_cast<std::size_t>(k)].begin, b[static_cast<std::size_t>(k)].begin);
                ASSERT_EQ(a[static_cast<std::size_t>(k)].end, b[static_cast<std::size_t>(k)].end);
              }
              ++compared;
            }
        EXPECT_GT(compared, 1000u);
        for (std::uint32_t i = 0; i < q.size(); ++i) ASSERT_EQ(dense.cell_end(i), hashed.cell_end(i)) << i;
      }
      parallel::set_thread_count(before);
    }
}

TYPED_TEST(CellGridTest, RefusesADenseTableBeyondItsLimit) {
  using Real = TypeParam;
  auto p = random_particles<Real>(100, 1.0, 1);
  p.position.x[5] = Real(2000);
  p.position.y[6] = Real(2000);
  p.position.z[7] = Real(2000);  // 2·10^6 cells per axis
  spatial::ParticleOrder<Real> order;
  spatial::SortedCellGrid<Real> grid;
  grid.set_table(spatial::CellTable::Dense);
  EXPECT_THROW(order_and_view(order, grid, p, 0.001, 16, spatial::CellOrder::Rows), std::invalid_argument);
  grid.set_table(spatial::CellTable::Auto);
  EXPECT_TRUE(order_and_view(order, grid, p, 0.001, 16, spatial::CellOrder::Rows));
  EXPECT_FALSE(grid.dense());
}

TYPED_TEST(CellGridTest, RefusesParticlesSpreadOverMoreThanTheKeyRange) {
  using Real = TypeParam;
  auto p = random_particles<Real>(100, 1.0, 1);
  p.position.y[3] = Real(1e6);  // 10^6 / 0.01 = 10^8 cells > 2^21
  for (auto curve : kOrders) {
    spatial::ParticleOrder<Real> order;
    spatial::SortedCellGrid<Real> grid;
    EXPECT_FALSE(order_and_view(order, grid, p, 0.01, 16, curve));
    EXPECT_FALSE(order.cells_fit());
    EXPECT_TRUE(order_and_view(order, grid, p, 1.0, 16, curve));
  }
}

TYPED_TEST(CellGridTest, RejectsNonFinitePositions) {
  using Real = TypeParam;
  auto p = random_particles<Real>(100, 1.0, 1);
  p.position.z[42] = std::numeric_limits<Real>::quiet_NaN();
  spatial::ParticleOrder<Real> order;
  spatial::SortedCellGrid<Real> grid;
  EXPECT_THROW(order_and_view(order, grid, p, 0.1, 16, spatial::CellOrder::Rows), std::runtime_error);
  p.position.z[42] = std::numeric_limits<Real>::infinity();
  EXPECT_THROW(order_and_view(order, grid, p, 0.1, 16, spatial::CellOrder::Morton), std::runtime_error);
}

// The order's reorder moves every field (built-in, extra, internal, real and
// integer) with its particle, keeps the ids, and counts an epoch when
// anything moved.
TYPED_TEST(CellGridTest, TheOrderMovesEveryFieldAndKeepsIds) {
  using Real = TypeParam;
  auto p = random_particles<Real>(1000, 1.0, 17);
  const std::size_t extra = p.add_field("extra", 3);
  const std::size_t internal = p.add_field("internal", 1, FieldUse::Internal);
  const std::size_t kind = p.add_int_field("kind");
  const std::size_t flag = p.add_int_field("flag", FieldUse::Internal);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.velocity.y[i] = Real(2 * i);
    p.acceleration_prev.z[i] = Real(3 * i);
    p.density[i] = Real(4 * i);
    p.pressure[i] = Real(5 * i);
    p.extra(extra, 2)[i] = Real(6 * i);
    p.extra(internal)[i] = Real(7 * i);
    p.int_field(kind)[i] = static_cast<std::int32_t>(i % 7) - 3;
    p.int_field(flag)[i] = -static_cast<std::int32_t>(i);
    p.id[i] = 1000000 + i;
  }
  for (auto curve : kOrders) {
    spatial::ParticleOrder<Real> order;
    spatial::SortedCellGrid<Real> grid;
    auto q = p;
    const auto epoch = order.epoch();
    ASSERT_TRUE(order_and_view(order, grid, q, 0.1, 32, curve));
    EXPECT_NE(order.epoch(), epoch);
    std::vector<bool> seen(p.size(), false);
    for (std::size_t k = 0; k < q.size(); ++k) {
      const std::size_t i = q.id[k] - 1000000;
      ASSERT_LT(i, p.size());
      EXPECT_FALSE(seen[i]);
      seen[i] = true;
      EXPECT_EQ(q.position.x[k], p.position.x[i]);
      EXPECT_EQ(q.velocity.y[k], p.velocity.y[i]);
      EXPECT_EQ(q.acceleration_prev.z[k], p.acceleration_prev.z[i]);
      EXPECT_EQ(q.mass[k], p.mass[i]);
      EXPECT_EQ(q.density[k], p.density[i]);
      EXPECT_EQ(q.pressure[k], p.pressure[i]);
      EXPECT_EQ(q.extra(extra, 2)[k], p.extra(extra, 2)[i]);
      EXPECT_EQ(q.extra(internal)[k], p.extra(internal)[i]);
      EXPECT_EQ(q.int_field(kind)[k], p.int_field(kind)[i]);
      EXPECT_EQ(q.int_field(flag)[k], p.int_field(flag)[i]);
      if (k > 0) {
        EXPECT_LE(order.keys()[k - 1], order.keys()[k]);
      }
    }
    // Sorted particles sort to themselves: no move, no new epoch.
    const auto settled = order.epoch();
    order.update(q, 32);
    EXPECT_EQ(order.epoch(), settled);
  }
}

TYPED_TEST(CellGridTest, OrderIsTheSameForOneTwoAndThreeThreads) {
  using Real = TypeParam;
  const auto p = random_particles<Real>(40000, 1.0, 23);
  const int before = parallel::thread_count();
  for (auto cell_order : kOrders) {
    std::vector<std::uint64_t> first;
    for (int threads : {1, 2, 3}) {
      parallel::set_thread_count(threads);
      spatial::ParticleOrder<Real> order;
      spatial::SortedCellGrid<Real> grid;
      auto q = p;
      ASSERT_TRUE(order_and_view(order, grid, q, 0.03, 256, cell_order, 0.004));
      if (first.empty())
        first = ids_of(q);
      else
        EXPECT_EQ(ids_of(q), first) << threads << " threads, " << order_name(cell_order);
    }
  }
  parallel::set_thread_count(before);
}

TEST(CellOrder, MortonKeysInterleaveTheCoordinateBits) {
  SplitMix64 rng(4);
  for (int t = 0; t < 1000; ++t) {
    const std::uint64_t x = rng.next() & 0x1fffff, y = rng.next() & 0x1fffff, z = rng.next() & 0x1fffff;
    const std::uint64_t k = spatial::morton_key(x, y, z);
    // The slow twin: bit by bit.
    std::uint64_t slow = 0;
    for (int b = 0; b < 21; ++b)
      slow |= ((x >> b) & 1) << (3 * b) | ((y >> b) & 1) << (3 * b + 1) | ((z >> b) & 1) << (3 * b + 2);
    ASSERT_EQ(k, slow);
    EXPECT_EQ(spatial::morton_compact(k), x);
    EXPECT_EQ(spatial::morton_compact(k >> 1), y);
    EXPECT_EQ(spatial::morton_compact(k >> 2), z);
  }
}

// Morton order in a long thin box: the key space (2^(3·bits of the longest
// axis)) is far larger than the cells, so the lookup is sparse, and cells at
// the far end of short axes are clipped.
TYPED_TEST(CellGridTest, MortonFindsTheBruteForcePairsInAThinBox) {
  using Real = TypeParam;
  auto p = random_particles<Real>(3000, 1.0, 31);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.position.x[i] *= Real(6);
    p.position.z[i] *= Real(0.1);
  }
  const Real h = Real(0.07);
  const Pairs expected = spatial::brute_force_pairs(p, h);
  ASSERT_GT(expected.size(), 3000u);
  for (auto order : kOrders) EXPECT_EQ(grid_pairs(p, h, 128, nullptr, order), expected) << order_name(order);
}

// The Verlet skin: particles drift a random walk for many steps; the order is
// sorted only when a particle moved more than skin/2, and scanning the grid's
// (stale) ranges must still find exactly the brute-force pairs of the current
// positions every step.
TYPED_TEST(CellGridTest, SkinFindsTheBruteForcePairsEveryStepWhileParticlesMove) {
  using Real = TypeParam;
  const Real h = Real(0.08);
  for (auto curve : kOrders)
    for (double skin : {0.25 * h}) {
      auto q = random_particles<Real>(700, 1.0, 41);
      // Velocities: most slow, a few fast (up to ~0.1 skin per step), so that
      // about one step in six needs a sort.
      SplitMix64 rng(43);
      for (std::size_t i = 0; i < q.size(); ++i) {
        const double speed = (i % 61 == 0 ? 0.06 : 0.01) * skin;
        for (int a = 0; a < 3; ++a) q.velocity[a][i] = Real(speed * (2 * rng.uniform() - 1));
      }
      spatial::ParticleOrder<Real> order;
      spatial::SortedCellGrid<Real> grid;
      const int steps = 40;
      for (int step = 0; step < steps; ++step) {
        ASSERT_TRUE(order_and_view(order, grid, q, double(h), 64, curve, skin));
        // Brute force on a copy indexed by id.
        ParticleSet<Real> by_id(q.size());
        for (std::size_t i = 0; i < q.size(); ++i) {
          by_id.position.set(q.id[i], q.position.get(i));
          by_id.id[q.id[i]] = q.id[i];
        }
        ASSERT_EQ(pairs_of(grid, q, h), spatial::brute_force_pairs(by_id, h))
            << "step " << step << ", skin " << skin << ", " << order_name(curve);
        for (std::size_t i = 0; i < q.size(); ++i)  // drift; bounce off the unit box's walls
          for (int a = 0; a < 3; ++a) {
            Real& x = q.position[a][i];
            x += q.velocity[a][i];
            if (x < Real(0) || x > Real(1)) {
              q.velocity[a][i] = -q.velocity[a][i];
              x = std::clamp(x, Real(0), Real(1));
            }
          }
      }
      EXPECT_GT(order.sorts(), 2u) << skin;               // the fast particles force sorts
      EXPECT_LT(order.sorts(), std::uint64_t(steps / 2)) << skin;  // ... but most steps reuse the order
    }
}

// The worst case of the skin: two particles two cells apart at the sort
// (just over one cell length h + skin between them) run head-on at each other.
// They become neighbours only after each moved about skin/2, so the order
// must sort just in time; an order that waited longer would miss the pair.
TYPED_TEST(CellGridTest, SkinCatchesTwoParticlesRunningHeadOn) {
  using Real = TypeParam;
  const double h = 0.1, skin = 0.02;
  for (auto curve : kOrders) {
    spatial::ParticleOrder<Real> order;
    spatial::SortedCellGrid<Real> grid;
    ParticleSet<Real> q(3);
    for (std::size_t i = 0; i < 3; ++i) q.id[i] = i;
    const double c = spatial::SortedCellGrid<Real>::cell_length_for(h, skin), delta = 1e-4;
    ASSERT_GT(c, h + skin);
    // An anchor at the origin fixes the cell boundaries at multiples of c.
    q.position.set(0, Vec3d{0, 0.5, 0.5}.cast<Real>());
    q.position.set(1, Vec3d{c - delta, 0.5, 0.5}.cast<Real>());
    q.position.set(2, Vec3d{2 * c + delta, 0.5, 0.5}.cast<Real>());
    int steps_as_neighbours = 0;
    for (int step = 0; step < 40; ++step) {
      ASSERT_TRUE(order_and_view(order, grid, q, h, 8, curve, skin));
      EXPECT_EQ(grid.cell_length(), c);
      ParticleSet<Real> by_id(q.size());
      for (std::size_t i = 0; i < q.size(); ++i) {
        by_id.position.set(q.id[i], q.position.get(i));
        by_id.id[q.id[i]] = q.id[i];
      }
      const Pairs expected = spatial::brute_force_pairs(by_id, Real(h));
      steps_as_neighbours += expected.size() > 0;
      ASSERT_EQ(pairs_of(grid, q, Real(h)), expected) << "step " << step << ", " << order_name(curve);
      for (std::size_t i = 0; i < q.size(); ++i) {  // ids 1 and 2 approach by 0.1 skin each per step
        if (q.id[i] == 1) q.position.x[i] += Real(0.1 * skin);
        if (q.id[i] == 2) q.position.x[i] -= Real(0.1 * skin);
      }
    }
    EXPECT_GT(steps_as_neighbours, 0);
    EXPECT_GE(order.sorts(), 2u);
  }
}

TYPED_TEST(CellGridTest, TheOrderSortsAgainWhenTheParticlesChange) {
  using Real = TypeParam;
  auto p = random_particles<Real>(500, 1.0, 7);
  spatial::ParticleOrder<Real> order;
  order.set_request({true, 0.2, 0.05, spatial::CellOrder::Rows});  // a skin of 0.1
  EXPECT_TRUE(order.update(p, 32));  // the first sort
  EXPECT_FALSE(order.update(p, 32));
  const auto at = [&](std::uint64_t id) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.id[i] == id) return i;
    return p.size();
  };
  p.position.y[at(123)] += Real(0.049);
  EXPECT_FALSE(order.update(p, 32));
  p.position.y[at(123)] += Real(0.002);  // 0.051 > skin/2
  EXPECT_TRUE(order.update(p, 32));
  const auto epoch = order.epoch();
  order.touch();  // someone else changed the particles
  EXPECT_NE(order.epoch(), epoch);
  EXPECT_TRUE(order.update(p, 32));
  p.resize(499);
  EXPECT_TRUE(order.update(p, 32));
  p.position.x[9] = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THROW(order.update(p, 32), std::runtime_error);
}

// A checkpointed order (its reference positions travel as a particle field)
// decides as the uninterrupted one: resume() rebuilds the keys without a sort.
TYPED_TEST(CellGridTest, AResumedOrderKeepsTheSkinsDecisions) {
  using Real = TypeParam;
  auto p = random_particles<Real>(800, 1.0, 12);
  spatial::ParticleOrder<Real> order;
  const spatial::OrderRequest request{true, 0.12, 0.01, spatial::CellOrder::Morton};
  order.set_request(request);
  order.update(p, 64);
  for (std::size_t i = 0; i < p.size(); ++i) p.position.x[i] += Real(0.004 * double(i % 3));  // within skin/2
  auto copy = p;  // what a checkpoint holds, the reference positions included
  spatial::ParticleOrder<Real> resumed;
  resumed.set_request(request);
  resumed.resume(copy, 64);
  ASSERT_TRUE(resumed.valid());
  EXPECT_FALSE(order.update(p, 64));
  EXPECT_FALSE(resumed.update(copy, 64));
  EXPECT_TRUE(std::equal(order.keys().begin(), order.keys().end(), resumed.keys().begin(), resumed.keys().end()));
  for (std::size_t i = 0; i < p.size(); ++i) p.position.x[i] += Real(0.008), copy.position.x[i] += Real(0.008);
  EXPECT_TRUE(order.update(p, 64));
  EXPECT_TRUE(resumed.update(copy, 64));
  EXPECT_EQ(ids_of(p), ids_of(copy));
}

}  // namespace
