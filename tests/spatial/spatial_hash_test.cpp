// The spatial hash against its slow twin, brute force.
#include "swirl/spatial/spatial_hash.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "swirl/core/random.hpp"
#include "swirl/parallel/counting_sort.hpp"
#include "swirl/spatial/brute_force.hpp"
#include "swirl/spatial/hash_statistics.hpp"

namespace {

using namespace swirl;
using namespace swirl::spatial;
using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

template <class Real>
class SpatialHashTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SpatialHashTest, Precisions);

// n particles uniformly in [lo, lo + side)³, some negative coordinates included.
template <class Real>
ParticleSet<Real> random_particles(std::size_t n, double lo, double side, std::uint64_t seed) {
  ParticleSet<Real> p(n);
  SplitMix64 rng(seed);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) p.position[axis][i] = Real(lo + side * rng.uniform());
    p.mass[i] = Real(1);
    p.id[i] = i;
  }
  return p;
}

template <class Real>
Pairs pairs_of(const NeighbourList<Real>& l) {
  Pairs pairs;
  for (std::size_t row = 0; row < l.rows(); ++row)
    for (std::size_t k = l.offsets[row]; k < l.offsets[row + 1]; ++k) pairs.emplace_back(l.row_particle[row], l.neighbour[k]);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

template <class Real>
NeighbourList<Real> search(const ParticleSet<Real>& p, Real h, std::uint32_t buckets, DuplicateCheck check,
                          SearchCounters* counters = nullptr, std::size_t block_size = 37) {
  SpatialHash<Real> hash;
  hash.build(p, h, buckets, block_size);
  NeighbourList<Real> lists;
  hash.find_neighbours(p, check, block_size, lists, [](auto, auto, auto, auto) {}, counters);
  return lists;
}

TYPED_TEST(SpatialHashTest, WithTheCheckOnTheListsAreExactlyTheBruteForcePairs) {
  using Real = TypeParam;
  for (std::uint32_t buckets : {1u, 2u, 7u, 97u, 1601u, 100003u}) {
    const auto p = random_particles<Real>(1000, -0.7, 1.9, buckets);
    const Real h = Real(0.15);
    const auto lists = search(p, h, buckets, DuplicateCheck::BeforeDistance);
    ASSERT_EQ(lists.rows(), p.size());
    std::vector<int> rows_of(p.size(), 0);
    for (auto i : lists.row_particle) ++rows_of[i];
    EXPECT_TRUE(std::all_of(rows_of.begin(), rows_of.end(), [](int c) { return c == 1; }));
    const auto expected = brute_force_pairs(p, h);
    ASSERT_GT(expected.size(), 1000u);  // a meaningful number of pairs
    EXPECT_EQ(pairs_of(lists), expected) << "buckets = " << buckets;
    // r² is stored exactly as the shared distance function computes it.
    for (std::size_t row = 0; row < lists.rows(); ++row)
      for (std::size_t k = lists.offsets[row]; k < lists.offsets[row + 1]; ++k) {
        const auto i = lists.row_particle[row], j = lists.neighbour[k];
        ASSERT_EQ(lists.r2[k], distance2(p.position.x[i], p.position.y[i], p.position.z[i], p.position.x[j],
                                         p.position.y[j], p.position.z[j]));
      }
  }
}

// The thesis's serial table build (one thread, its PPE) gives the table of
// the parallel build: the stable order is unique.
TYPED_TEST(SpatialHashTest, TheSerialTableIsTheParallelTable) {
  using Real = TypeParam;
  const int saved = parallel::thread_count();
  parallel::set_thread_count(3);
  const auto p = random_particles<Real>(20000, -0.5, 1.5, 31);
  SpatialHash<Real> parallel_table, serial_table;
  parallel_table.build(p, Real(0.1), 16001u, 97);
  serial_table.build(p, Real(0.1), 16001u, 97, TableBuild::Serial);
  EXPECT_EQ(serial_table.order(), parallel_table.order());
  EXPECT_EQ(serial_table.offsets(), parallel_table.offsets());
  parallel::set_thread_count(saved);
}

// The thesis's precomputed neighbour hashes are, particle by particle, the
// hashes of the 26 cells around its own in the search's scan order, and the
// search that reads them makes the lists of the search that hashes on the fly:
// the same rows, neighbours, r² bits and counters, for every place of the
// duplicate check, on tables with many collisions, on 3 threads. Two particles
// sit at the int32 clamp of the cell coordinates, where the neighbour cells wrap.
TYPED_TEST(SpatialHashTest, PrecomputedNeighbourHashesGiveTheListsOfTheSearchThatHashesOnTheFly) {
  using Real = TypeParam;
  const int saved = parallel::thread_count();
  parallel::set_thread_count(3);
  for (std::uint32_t buckets : {1u, 3u, 11u, 389u, 1601u}) {
    auto p = random_particles<Real>(900, -0.4, 1.2, 53 + buckets);
    p.position.x[0] = p.position.x[1] = Real(1e30);  // cell i = INT32_MAX: its neighbour i + 1 wraps
    const Real h = Real(0.11);
    SpatialHash<Real> fly, pre;
    fly.build(p, h, buckets, 41);
    pre.build(p, h, buckets, 41, TableBuild::Parallel, NeighbourHashes::Precomputed);
    EXPECT_TRUE(fly.neighbour_hashes().empty());
    ASSERT_EQ(pre.neighbour_hashes().size(), p.size() * 26);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Cell c = pre.cells()[i];
      std::size_t at = i * 26;
      for (std::int64_t dk = -1; dk <= 1; ++dk)
        for (std::int64_t dj = -1; dj <= 1; ++dj)
          for (std::int64_t di = -1; di <= 1; ++di) {
            if (di == 0 && dj == 0 && dk == 0) continue;
            // The neighbour cell with 64-bit arithmetic, wrapped to 32 bits as the hash's unsigned products do.
            auto wrapped = [](std::int32_t x, std::int64_t d) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(x + d)); };
            const Cell n{wrapped(c.i, di), wrapped(c.j, dj), wrapped(c.k, dk)};
            ASSERT_EQ(pre.neighbour_hashes()[at++], hash_cell(n, buckets)) << "particle " << i;
          }
    }
    for (DuplicateCheck check : {DuplicateCheck::Off, DuplicateCheck::BeforeDistance, DuplicateCheck::AfterDistance}) {
      NeighbourList<Real> a, b;
      SearchCounters ca, cb;
      fly.find_neighbours(p, check, 41, a, [](auto, auto, auto, auto) {}, &ca);
      pre.find_neighbours(p, check, 41, b, [](auto, auto, auto, auto) {}, &cb);
      EXPECT_EQ(b.row_particle, a.row_particle);
      EXPECT_EQ(b.offsets, a.offsets);
      EXPECT_EQ(b.neighbour, a.neighbour) << buckets << " buckets";
      ASSERT_EQ(b.r2.size(), a.r2.size());
      EXPECT_EQ(std::memcmp(b.r2.data(), a.r2.data(), a.r2.size() * sizeof(Real)), 0);
      EXPECT_EQ(cb.tests, ca.tests);
      EXPECT_EQ(cb.redundant_tests, ca.redundant_tests);
      EXPECT_EQ(cb.interactions, ca.interactions);
    }
    // A build without the option drops the hashes: the search hashes on the fly again.
    pre.build(p, h, buckets, 41);
    EXPECT_TRUE(pre.neighbour_hashes().empty());
  }
  parallel::set_thread_count(saved);
}

// The thesis's place for the check (after the distance test) and ours (before
// it) keep the same pairs, in the same order, on tables with many collisions.
TYPED_TEST(SpatialHashTest, TheCheckAfterTheDistanceTestKeepsTheSamePairsAsBefore) {
  using Real = TypeParam;
  for (std::uint32_t buckets : {1u, 3u, 11u, 389u, 1601u}) {
    const auto p = random_particles<Real>(600, 0.0, 1.0, 7 + buckets);
    const Real h = Real(0.12);
    const auto before = search(p, h, buckets, DuplicateCheck::BeforeDistance);
    const auto after = search(p, h, buckets, DuplicateCheck::AfterDistance);
    EXPECT_EQ(after.row_particle, before.row_particle);
    EXPECT_EQ(after.offsets, before.offsets);
    EXPECT_EQ(after.neighbour, before.neighbour);
    EXPECT_EQ(pairs_of(after), brute_force_pairs(p, h)) << buckets << " buckets";
  }
}

TYPED_TEST(SpatialHashTest, WithTheCheckOffTheExtraPairsAreTheReportedDuplicates) {
  using Real = TypeParam;
  for (std::uint32_t buckets : {1u, 3u, 11u, 389u}) {  // tiny tables force collisions among the 27 cells
    const auto p = random_particles<Real>(600, 0.0, 1.0, 7 + buckets);
    const Real h = Real(0.12);
    const auto unchecked = pairs_of(search(p, h, buckets, DuplicateCheck::Off));
    const auto checked = pairs_of(search(p, h, buckets, DuplicateCheck::BeforeDistance));
    // Without the check every true pair is still found, some more than once.
    Pairs unique = unchecked;
    unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
    EXPECT_EQ(unique, checked);
    const auto stats = hash_statistics(p, h, buckets, 64);
    EXPECT_EQ(stats.interactions, checked.size());
    EXPECT_EQ(stats.duplicate_interactions, unchecked.size() - checked.size());
    if (buckets <= 11) {
      EXPECT_GT(stats.duplicate_interactions, 0u);
    }
  }
}

// Table 5.2's counts, recomputed by brute force from the definitions.
TYPED_TEST(SpatialHashTest, HashStatisticsMatchBruteForceCounts) {
  using Real = TypeParam;
  const Real h = Real(0.1);
  for (std::uint32_t buckets : {5u, 61u, 1601u}) {
    const auto p = random_particles<Real>(500, -0.3, 0.9, 99 + buckets);
    const auto s = hash_statistics(p, h, buckets, 50);

    std::vector<Cell> cells(p.size());
    std::vector<std::uint32_t> bucket(p.size());
    std::map<std::uint32_t, std::set<std::tuple<int, int, int>>> cells_in_bucket;
    for (std::size_t i = 0; i < p.size(); ++i) {
      cells[i] = cell_of(p.position.x[i], p.position.y[i], p.position.z[i], h);
      bucket[i] = hash_cell(cells[i], buckets);
      cells_in_bucket[bucket[i]].insert({cells[i].i, cells[i].j, cells[i].k});
    }
    std::uint64_t collisions = 0;
    for (const auto& [b, set] : cells_in_bucket) collisions += set.size() > 1 ? 1 : 0;
    EXPECT_EQ(s.empty_buckets, buckets - cells_in_bucket.size());
    EXPECT_EQ(s.buckets_with_collisions, collisions);

    std::uint64_t tests = 0, redundant = 0, duplicates = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      std::vector<std::pair<Cell, std::uint32_t>> searched;
      for (int dk = -1; dk <= 1; ++dk)
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const Cell c{cells[i].i + di, cells[i].j + dj, cells[i].k + dk};
            searched.emplace_back(c, hash_cell(c, buckets));
          }
      for (std::size_t j = 0; j < p.size(); ++j) {
        if (j == i) continue;
        int found = 0;
        for (const auto& [c, b] : searched) {
          if (bucket[j] != b) continue;
          ++tests;
          if (!(cells[j] == c)) ++redundant;
          ++found;
        }
        const Real r2 = distance2(p.position.x[i], p.position.y[i], p.position.z[i], p.position.x[j],
                                  p.position.y[j], p.position.z[j]);
        if (within(r2, h * h)) duplicates += static_cast<std::uint64_t>(found - 1);
      }
    }
    EXPECT_EQ(s.tests, tests);
    EXPECT_EQ(s.redundant_tests, redundant);
    EXPECT_EQ(s.duplicate_interactions, duplicates);
    EXPECT_EQ(s.interactions, brute_force_pairs(p, h).size());
  }
}

TYPED_TEST(SpatialHashTest, ListsAreIdenticalForAnyThreadCount) {
  using Real = TypeParam;
  const auto p = random_particles<Real>(5000, 0.0, 1.0, 5);
  auto with = [&](int threads) {
    parallel::set_thread_count(threads);
    return search(p, Real(0.08), 8001u, DuplicateCheck::BeforeDistance, nullptr, 64);
  };
  const auto one = with(1);
  for (int t : {2, 3}) {
    const auto other = with(t);
    EXPECT_EQ(other.row_particle, one.row_particle);
    EXPECT_EQ(other.offsets, one.offsets);
    EXPECT_EQ(other.neighbour, one.neighbour);
    EXPECT_EQ(other.r2, one.r2);
  }
}

TEST(TeschnerHash, MatchesTheFormulaWithWrapAround) {
  // ((uint32)(-1)·P1 ^ 2·P2 ^ 3·P3) mod 24001, by hand with 32-bit wrap-around.
  const std::uint32_t h = ((0xffffffffu * 73856093u) ^ (2u * 19349663u) ^ (3u * 83492791u)) % 24001u;
  EXPECT_EQ(hash_cell(Cell{-1, 2, 3}, 24001u), h);
  EXPECT_EQ(cell_of(-0.5, 0.0, 1.99, 1.0), (Cell{-1, 0, 1}));
  EXPECT_EQ(cell_of(2.0, -2.0, 1e30, 1.0), (Cell{2, -2, 2147483647}));
}

TEST(CountingSort, IsTheStableSortForAnyThreadCount) {
  SplitMix64 rng(3);
  std::vector<std::uint32_t> keys(50000);
  for (auto& k : keys) k = static_cast<std::uint32_t>(rng.next() % 1000);
  std::vector<std::uint32_t> expected(keys.size());
  for (std::uint32_t i = 0; i < expected.size(); ++i) expected[i] = i;
  std::stable_sort(expected.begin(), expected.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
  for (int threads : {1, 2, 3}) {
    parallel::set_thread_count(threads);
    parallel::CountingSort sort;
    sort.sort(keys, 1000);
    EXPECT_EQ(sort.order(), expected);
    ASSERT_EQ(sort.offsets().size(), 1001u);
    for (std::uint32_t k = 0; k < 1000; ++k)
      for (auto s = sort.offsets()[k]; s < sort.offsets()[k + 1]; ++s) ASSERT_EQ(keys[sort.order()[s]], k);
  }
}

}  // namespace
