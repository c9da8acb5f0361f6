// The global key order across ranks (dist/key_order.hpp, dist/key_cuts.hpp),
// run by CTest on 1-4 ranks: whatever the rank count, the ranks' particles in
// rank order are the one-rank stable sort by key, after a first sort from an
// uneven start and after a step that moves particles across the cuts; the cuts
// balance a deterministic cost.
#include "swirl/dist/key_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <vector>

#include "dist/lattice_block.hpp"
#include "swirl/dist/key_cuts.hpp"

namespace swirl::dist {
namespace {

constexpr std::uint64_t kParticles = 3000;

// A position in [0,1)^3 for global particle g (the same on every rank).
double coordinate(std::uint64_t g, int axis) { return test::unit_hash(g, static_cast<std::uint64_t>(axis)); }

// A coarse key (8 cells per axis, Morton-interleaved, in the top bits of a
// 63-bit key): many particles share a key, so the tie order is tested.
std::uint64_t coarse_key(double x, double y, double z) {
  std::uint64_t key = 0;
  const auto cell = [](double v) { return static_cast<std::uint64_t>(std::clamp(v, 0.0, 0.999999) * 8); };
  const std::uint64_t c[3] = {cell(x), cell(y), cell(z)};
  for (int bit = 2; bit >= 0; --bit)
    for (int axis = 2; axis >= 0; --axis) key = (key << 1) | ((c[axis] >> bit) & 1u);
  return key << 54;
}

struct Local {
  ParticleSet<double> particles;
  std::vector<std::uint64_t> keys;
  std::uint64_t first = 0;
  std::size_t temperature = 0, tag = 0;
};

// Rank r starts with the uneven range [N·r²/s², N·(r+1)²/s²) of the initial order.
Local initial(const Communicator& comm) {
  const auto s = static_cast<std::uint64_t>(comm.size()), r = static_cast<std::uint64_t>(comm.rank());
  Local l;
  l.first = kParticles * r * r / (s * s);
  const std::uint64_t end = kParticles * (r + 1) * (r + 1) / (s * s);
  l.particles.resize(end - l.first);
  l.temperature = l.particles.add_field("temperature", 1);
  l.tag = l.particles.add_int_field("tag");
  for (std::uint64_t g = l.first; g < end; ++g) {
    const std::size_t i = g - l.first;
    l.particles.position.x[i] = coordinate(g, 0);
    l.particles.position.y[i] = coordinate(g, 1);
    l.particles.position.z[i] = coordinate(g, 2);
    l.particles.mass[i] = 1.0 + static_cast<double>(g % 5);
    l.particles.id[i] = g;
    l.particles.extra(l.temperature)[i] = 300.0 + static_cast<double>(g) * 0.25;
    l.particles.int_field(l.tag)[i] = static_cast<std::int32_t>(g % 1000) - 500;
  }
  return l;
}

void compute_keys(Local& l) {
  l.keys.resize(l.particles.size());
  for (std::size_t i = 0; i < l.keys.size(); ++i)
    l.keys[i] = coarse_key(l.particles.position.x[i], l.particles.position.y[i], l.particles.position.z[i]);
}

// One step's motion: a shear along x that wraps around, enough to move many
// particles across every cut.
void move(Local& l) {
  for (std::size_t i = 0; i < l.particles.size(); ++i) {
    double& x = l.particles.position.x[i];
    x = std::fmod(x + 0.3 * l.particles.position.y[i] + 0.05, 1.0);
  }
}

// A one-rank record of what the test compares, in global order.
struct Row {
  std::uint64_t id, key;
  double x, temperature;
  std::int32_t tag;
};

std::vector<Row> gather_rows(const Communicator& comm, const Local& l) {
  Bytes mine(l.particles.size() * sizeof(Row));
  for (std::size_t i = 0; i < l.particles.size(); ++i) {
    const Row row{l.particles.id[i], l.keys[i], l.particles.position.x[i], l.particles.extra(l.temperature)[i],
                  l.particles.int_field(l.tag)[i]};
    std::memcpy(mine.data() + i * sizeof(Row), &row, sizeof(Row));
  }
  std::vector<Row> rows;
  for (const Bytes& b : comm.gather_to_root(mine)) {
    const std::size_t first = rows.size();
    rows.resize(first + b.size() / sizeof(Row));
    std::memcpy(rows.data() + first, b.data(), b.size());
  }
  return rows;
}

// The one-rank reference: rows (in the previous global order) stably sorted by key.
std::vector<Row> stable_by_key(std::vector<Row> rows) {
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.key < b.key; });
  return rows;
}

void expect_same(const std::vector<Row>& got, const std::vector<Row>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t g = 0; g < got.size(); ++g) {
    ASSERT_EQ(got[g].id, want[g].id) << "global index " << g;
    EXPECT_EQ(got[g].key, want[g].key);
    EXPECT_EQ(std::memcmp(&got[g].x, &want[g].x, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&got[g].temperature, &want[g].temperature, sizeof(double)), 0);
    EXPECT_EQ(got[g].tag, want[g].tag);
  }
}

void expect_in_own_range(const Communicator& comm, const Local& l, const std::vector<std::uint64_t>& cuts) {
  for (std::uint64_t key : l.keys) EXPECT_EQ(owner_of(key, cuts), comm.rank());
  EXPECT_TRUE(std::is_sorted(l.keys.begin(), l.keys.end()));
}

std::vector<std::uint64_t> unit_costs(const Local& l) {
  std::vector<std::uint64_t> costs(l.particles.size());
  for (std::size_t i = 0; i < costs.size(); ++i) costs[i] = 1 + l.particles.id[i] % 7;
  return costs;
}

TEST(KeyOrder, FirstSortAndMigrationGiveTheOneRankStableOrder) {
  const Communicator& comm = Communicator::world();
  Local l = initial(comm);
  compute_keys(l);
  const std::vector<Row> start = gather_rows(comm, l);

  const std::vector<std::uint64_t> cuts = balanced_cut_keys(comm, l.keys, unit_costs(l));
  ASSERT_EQ(cuts.size(), static_cast<std::size_t>(comm.size() - 1));
  Distribution d = distribute_in_key_order(comm, l.particles, l.keys, l.first, cuts);
  l.first = d.first_global_index;
  EXPECT_EQ(d.global_count, kParticles);
  EXPECT_EQ(l.first, comm.exclusive_prefix_sum(l.particles.size()));
  expect_in_own_range(comm, l, cuts);
  const std::vector<Row> first_sort = gather_rows(comm, l);
  if (comm.is_root()) expect_same(first_sort, stable_by_key(start));

  // A step: particles move, keys change, the same cuts (migration only).
  move(l);
  compute_keys(l);
  const std::vector<Row> moved = gather_rows(comm, l);
  d = distribute_in_key_order(comm, l.particles, l.keys, l.first, cuts);
  l.first = d.first_global_index;
  expect_in_own_range(comm, l, cuts);
  const std::uint64_t migrated = comm.sum(static_cast<std::uint64_t>(d.sent_away));
  if (comm.size() > 1) {
    EXPECT_GT(migrated, 0u) << "the step must move particles across a cut";
  }
  const std::vector<Row> second_sort = gather_rows(comm, l);
  if (comm.is_root()) expect_same(second_sort, stable_by_key(moved));
}

// A cell frame's keys use few bits (ParticleOrder sorts its frame's key_bits):
// the coarse keys moved to the low 9 bits, sorted by those 9 alone.
TEST(KeyOrder, SortsOnlyTheKeysBitsAndLeavesAnOrderedRangeInPlace) {
  const Communicator& comm = Communicator::world();
  constexpr unsigned kBits = 9;
  Local l = initial(comm);
  compute_keys(l);
  for (std::uint64_t& key : l.keys) key >>= 63 - kBits;
  const std::vector<Row> start = gather_rows(comm, l);
  const std::vector<std::uint64_t> cuts = balanced_cut_keys(comm, l.keys, unit_costs(l));
  DistributeWorkspace<double> work;
  Distribution d = distribute_in_key_order(comm, l.particles, l.keys, l.first, cuts, kBits, work);
  l.first = d.first_global_index;
  const std::vector<Row> sorted = gather_rows(comm, l);
  if (comm.is_root()) expect_same(sorted, stable_by_key(start));

  // Nothing moved: the same keys and cuts keep every particle where it is,
  // without the gather (which would swap in other arrays).
  const double* x_before = l.particles.position.x.data();
  d = distribute_in_key_order(comm, l.particles, l.keys, l.first, cuts, kBits, work);
  EXPECT_EQ(d.sent_away, 0u);
  EXPECT_EQ(d.first_global_index, l.first);
  EXPECT_EQ(l.particles.position.x.data(), x_before) << "a range already in order was gathered again";
  const std::vector<Row> again = gather_rows(comm, l);
  if (comm.is_root()) expect_same(again, sorted);

  // A key with bits above key_bits is refused (on the rank that holds it; every rank checks before sending).
  std::vector<std::uint64_t> keys = l.keys;
  if (!keys.empty()) {
    keys[0] |= std::uint64_t{1} << kBits;
    EXPECT_THROW(distribute_in_key_order(comm, l.particles, keys, l.first, cuts, kBits, work), std::invalid_argument);
  }
  EXPECT_THROW(distribute_in_key_order(comm, l.particles, l.keys, l.first, cuts, 0, work), std::invalid_argument);
}

TEST(KeyCuts, BalanceTheCostWithinOneKeysShare) {
  const Communicator& comm = Communicator::world();
  Local l = initial(comm);
  compute_keys(l);
  const std::vector<std::uint64_t> costs = unit_costs(l);
  const std::vector<std::uint64_t> cuts = balanced_cut_keys(comm, l.keys, costs);
  const std::vector<std::uint64_t> per_rank = cost_per_rank(comm, l.keys, costs, cuts);
  const std::uint64_t total = std::accumulate(per_rank.begin(), per_rank.end(), std::uint64_t{0});
  // The largest cost that one key (which no cut splits) carries, over all ranks.
  std::vector<std::uint64_t> per_key(512, 0);
  for (std::size_t i = 0; i < l.keys.size(); ++i) per_key[l.keys[i] >> 54] += costs[i];
  comm.sum(per_key);
  const std::uint64_t heaviest_key = *std::max_element(per_key.begin(), per_key.end());
  const auto ranks = static_cast<std::uint64_t>(comm.size());
  for (std::uint64_t c : per_rank) {
    EXPECT_LE(c, (total + ranks - 1) / ranks + heaviest_key);
  }
  EXPECT_EQ(total, comm.sum(std::accumulate(costs.begin(), costs.end(), std::uint64_t{0})));
  // With 3000 particles in 512 keys, one key is a small share: close to even.
  EXPECT_LT(imbalance(per_rank), 1.0 + 2.0 * static_cast<double>(heaviest_key * ranks) / static_cast<double>(total));
}

TEST(KeyCuts, FallOnlyOnBoundariesOfTheirDepth) {
  const Communicator& comm = Communicator::world();
  Local l = initial(comm);
  compute_keys(l);
  const std::vector<std::uint64_t> costs = unit_costs(l);
  for (int depth : {1, 2, 5}) {
    const std::vector<std::uint64_t> cuts = balanced_cut_keys(comm, l.keys, costs, depth);
    const std::uint64_t cell = std::uint64_t{1} << (3 * (kKeyDepth - depth));
    for (std::uint64_t c : cuts) {
      EXPECT_TRUE(c % cell == 0 || c == ~std::uint64_t{0}) << "depth " << depth << " cut " << c;
    }
    EXPECT_TRUE(std::is_sorted(cuts.begin(), cuts.end()));
  }
  EXPECT_THROW(balanced_cut_keys(comm, l.keys, costs, 22), std::invalid_argument);
}

TEST(KeyOrder, MoreRanksThanParticlesLeavesSomeRanksEmpty) {
  const Communicator& comm = Communicator::world();
  ParticleSet<double> p(comm.is_root() ? 2 : 0);
  std::vector<std::uint64_t> keys(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.id[i] = i;
    keys[i] = (2 - i) << 60;  // reversed
  }
  const std::vector<std::uint64_t> cuts = balanced_cut_keys(comm, keys, std::vector<std::uint64_t>(keys.size(), 1));
  const Distribution d = distribute_in_key_order(comm, p, keys, 0, cuts);
  EXPECT_EQ(d.global_count, 2u);
  const std::vector<std::uint64_t> counts = comm.all_gather(p.size());
  EXPECT_EQ(std::accumulate(counts.begin(), counts.end(), std::uint64_t{0}), 2u);
  if (comm.size() == 1) {
    ASSERT_EQ(p.size(), 2u);
    EXPECT_EQ(p.id[0], 1u);
    EXPECT_EQ(p.id[1], 0u);
  }
}

// owners_of() and sum_per_rank() (the few-cuts comparisons and the binary
// search beyond kFewCuts) against owner_of() per key, for 0 to 12 cuts with
// repeated cuts, a cut at 0, cuts at the keys themselves and the "no key
// above" cut (2^64 - 1).
TEST(KeyOrder, OwnersAndSumsPerRankAreOwnerOfsForAnyCutCount) {
  std::vector<std::uint64_t> keys(5000);
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = coarse_key(coordinate(i, 0), coordinate(i, 1), coordinate(i, 2));
  keys[7] = 0;
  keys[8] = ~std::uint64_t{0};
  for (std::size_t cuts = 0; cuts <= 12; ++cuts) {
    std::vector<std::uint64_t> cut_keys;
    for (std::size_t c = 0; c < cuts; ++c) cut_keys.push_back(keys[(c * 977) % keys.size()]);
    if (cuts >= 3) cut_keys[0] = 0, cut_keys[1] = cut_keys[2];
    if (cuts >= 5) cut_keys.back() = ~std::uint64_t{0};
    std::sort(cut_keys.begin(), cut_keys.end());
    std::vector<int> destination(keys.size(), -1);
    owners_of(keys, cut_keys, destination);
    std::vector<std::uint64_t> counts(cuts + 1, 0), costs(cuts + 1, 0), want_counts(cuts + 1, 0), want_costs(cuts + 1, 0);
    sum_per_rank(keys, cut_keys, [](std::size_t) { return std::uint64_t{1}; }, counts);
    sum_per_rank(keys, cut_keys, [](std::size_t i) { return std::uint64_t{i % 7 + 1}; }, costs);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const int owner = owner_of(keys[i], cut_keys);
      ASSERT_EQ(destination[i], owner) << cuts << " cuts, key " << i;
      ++want_counts[static_cast<std::size_t>(owner)];
      want_costs[static_cast<std::size_t>(owner)] += i % 7 + 1;
    }
    EXPECT_EQ(counts, want_counts) << cuts << " cuts";
    EXPECT_EQ(costs, want_costs) << cuts << " cuts";
  }
}

}  // namespace
}  // namespace swirl::dist
