// The ghosts of each rank (dist/halo.hpp), run by CTest on 1-4 ranks: the
// halo set equals a brute-force search over all pairs of the rank's particles
// and the others' (cells: the 27 around each own particle's cell; distance:
// every particle within h + skin of an own one is a ghost), the ghosts arrive
// with their fields at their global index, and after a step that moves
// particles across the cuts every particle is on the rank owning its key,
// none lost or duplicated, the order still the one-rank order.
#include "swirl/dist/halo.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <iostream>
#include <ostream>
#include <numeric>
#include <set>
#include <vector>

#include "dist/lattice_block.hpp"
#include "swirl/core/morton.hpp"
#include "swirl/dist/key_cuts.hpp"
#include "swirl/dist/key_order.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/distance.hpp"

namespace swirl::dist {
namespace {

using test::kH;
using test::kParticles;
using test::kSpacing;

constexpr std::size_t kTail = 7;

// A cell's integer coordinates from a particle key (the definition of the frame's cells).
std::array<std::int64_t, 3> cell_coordinates(const spatial::KeyFrame& f, std::uint64_t key) {
  const std::uint64_t cell = f.cell_of(key);
  if (f.curve == spatial::CellOrder::Rows)
    return {std::int64_t(cell % f.cells[0]), std::int64_t(cell / f.cells[0] % f.cells[1]),
            std::int64_t(cell / f.cells[0] / f.cells[1])};
  return {std::int64_t(morton_compact(cell)), std::int64_t(morton_compact(cell >> 1)),
          std::int64_t(morton_compact(cell >> 2))};
}

struct Case {
  spatial::CellOrder curve;
  double skin;      // m
  bool scattered;   // test::scatter(): one particle per six cells
};

void PrintTo(const Case& c, std::ostream* out) {
  *out << (c.curve == spatial::CellOrder::Rows ? "rows" : "morton") << ", skin " << c.skin
       << (c.scattered ? ", scattered" : ", lattice");
}

// One rank's state: its particles (own, and ghosts once inserted), keys, frame, cuts.
struct Rank {
  ParticleSet<double> p;
  std::vector<std::uint64_t> keys;
  spatial::KeyFrame frame;
  std::vector<std::uint64_t> cuts;
  Distribution d;
  Halo halo;
};

spatial::OrderRequest request_for(const Case& c) {
  return {true, spatial::SortedCellGrid<double>::cell_length_for(kH, c.skin), 0.5 * c.skin, c.curve};
}

// Frame, keys, the distributed sort (with the given cuts, or balanced ones), the halo.
void sort_and_find(const Communicator& comm, Rank& r, const Case& c, std::uint64_t first, bool new_cuts) {
  bool fits = false;
  r.frame = global_key_frame(comm, r.p, request_for(c), fits);
  ASSERT_TRUE(fits);
  r.keys = keys_in_frame(r.frame, r.p);
  if (new_cuts) r.cuts = balanced_cut_keys(comm, r.keys, std::vector<std::uint64_t>(r.keys.size(), 1));
  r.d = distribute_in_key_order(comm, r.p, r.keys, first, r.cuts);
  r.halo = Halo::find(comm, r.frame, r.keys, r.d.first_global_index, r.d.global_count, r.cuts, kTail);
}

// The whole set in the one-rank order: `all` in its current order, stably sorted by key in frame f.
ParticleSet<double> one_rank_order(const ParticleSet<double>& all, const spatial::KeyFrame& f) {
  const std::vector<std::uint64_t> keys = keys_in_frame(f, all);
  std::vector<std::size_t> order(all.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  ParticleSet<double> sorted = all;
  sorted.reorder(order);
  return sorted;
}

// Checks the rank's ghosts (inserted) against brute force over the whole set
// `global` (one-rank order), and returns {ghosts, ghosts within h of an own particle}.
std::array<std::uint64_t, 2> check_halo(const Communicator& comm, const Rank& r, const ParticleSet<double>& global,
                                        double skin) {
  const std::uint64_t first = r.d.first_global_index, n = r.halo.owned_count(), count = global.size();
  const IndexRange own = r.halo.owned();
  EXPECT_EQ(own.end - own.begin, n);
  // The own particles are the one-rank order's [first, first + n).
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(r.p.id[own.begin + i], global.id[first + i]) << "own " << i;

  const std::vector<std::uint64_t> global_keys = keys_in_frame(r.frame, global);
  const auto is_own = [&](std::uint64_t g) { return g >= first && g < first + n; };
  // Brute force: every other rank's particle in a cell next to (or in) the cell of an own one, and the tail.
  std::vector<std::uint64_t> want;
  std::uint64_t within = 0;
  const double reach2 = (kH + skin) * (kH + skin);
  for (std::uint64_t g = 0; g < count; ++g) {
    if (is_own(g)) continue;
    const auto cg = cell_coordinates(r.frame, global_keys[g]);
    bool near = g + kTail >= count, close = false;
    for (std::uint64_t i = first; i < first + n; ++i) {
      const auto ci = cell_coordinates(r.frame, global_keys[i]);
      if (std::abs(ci[0] - cg[0]) <= 1 && std::abs(ci[1] - cg[1]) <= 1 && std::abs(ci[2] - cg[2]) <= 1) near = true;
      const double r2 = spatial::distance2(global.position.x[i], global.position.y[i], global.position.z[i],
                                           global.position.x[g], global.position.y[g], global.position.z[g]);
      if (spatial::within(r2, reach2)) close = true;
      if (near && close) break;
    }
    if (near) want.push_back(g);
    if (close) {
      ++within;
      EXPECT_TRUE(near) << "particle " << g << " is within h + skin of rank " << comm.rank()
                        << " but in no cell next to its cells";
    }
  }
  std::vector<std::uint64_t> got;
  const auto gi = r.halo.global_index();
  // The local array is the global order with gaps: own particles at their place among the ghosts.
  EXPECT_TRUE(std::adjacent_find(gi.begin(), gi.end(), std::greater_equal<>()) == gi.end());
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(gi[own.begin + i], first + i);
  EXPECT_TRUE(std::is_sorted(r.keys.begin(), r.keys.end()));
  for (std::size_t i = 0; i < gi.size(); ++i)
    if (i < own.begin || i >= own.end) got.push_back(gi[i]);
  EXPECT_EQ(got, want) << "rank " << comm.rank() << " of " << comm.size();
  EXPECT_EQ(r.halo.ghost_count(), got.size());
  // Each ghost arrived with its key and fields, bit for bit.
  for (std::size_t i = 0; i < gi.size(); ++i) {
    const std::uint64_t g = gi[i];
    EXPECT_EQ(r.p.id[i], global.id[g]);
    EXPECT_EQ(r.keys[i], global_keys[g]);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(std::memcmp(&r.p.position[a][i], &global.position[a][g], sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(&r.p.velocity[a][i], &global.velocity[a][g], sizeof(double)), 0);
    }
    EXPECT_EQ(std::memcmp(&r.p.mass[i], &global.mass[g], sizeof(double)), 0);
  }
  return {got.size(), within};
}

class HaloTest : public ::testing::TestWithParam<Case> {};

TEST_P(HaloTest, EqualsTheBruteForceSearchBeforeAndAfterMigration) {
  const Communicator& comm = Communicator::world();
  const Case c = GetParam();
  const test::Slice slice = test::initial_slice(comm);
  Rank r;
  test::fill_block(r.p, slice.first, slice.end);
  if (c.scattered) test::scatter(r.p, slice.first);
  const std::size_t temperature = r.p.add_field("temperature", 1);
  for (std::size_t i = 0; i < r.p.size(); ++i) r.p.extra(temperature)[i] = 300.0 + double(r.p.id[i]);
  ParticleSet<double> all;
  test::fill_block(all, 0, kParticles);
  if (c.scattered) test::scatter(all, 0);
  all.add_field("temperature", 1);
  for (std::size_t i = 0; i < all.size(); ++i) all.extra(temperature)[i] = 300.0 + double(all.id[i]);

  sort_and_find(comm, r, c, slice.first, true);
  ParticleSet<double> global = one_rank_order(all, r.frame);
  r.halo.insert(comm, r.p, r.keys, {"position", "velocity", "mass"});
  EXPECT_EQ(r.p.size(), r.halo.owned_count() + r.halo.ghost_count());
  const auto first = check_halo(comm, r, global, c.skin);
  for (std::size_t i = 0; i < r.p.size(); ++i) {  // not sent: zero for ghosts, kept for the own particles
    const bool own = i >= r.halo.owned().begin && i < r.halo.owned().end;
    EXPECT_EQ(r.p.extra(temperature)[i], own ? 300.0 + double(r.p.id[i]) : 0.0);
  }
  // Exchange 2: a field the owners changed reaches every ghost.
  for (std::size_t i = r.halo.owned().begin; i < r.halo.owned().end; ++i) r.p.density[i] = double(r.p.id[i]) * 0.5;
  r.halo.refresh(comm, r.p, {"density", "temperature"});
  for (std::size_t i = 0; i < r.p.size(); ++i) {
    EXPECT_EQ(r.p.density[i], double(r.p.id[i]) * 0.5);
    EXPECT_EQ(r.p.extra(temperature)[i], 300.0 + double(r.p.id[i]));
  }
  const Traffic insert = r.halo.insert_traffic(), refresh = r.halo.refresh_traffic(), ask = r.halo.request_traffic();

  // A step: remove the ghosts, move, sort again with the same cuts (migration).
  r.halo.remove(r.p, r.keys);
  ASSERT_EQ(r.p.size(), r.halo.owned_count());
  for (std::size_t i = 0; i < r.p.size(); ++i) EXPECT_EQ(r.p.id[i], global.id[r.d.first_global_index + i]);
  test::drift(r.p, 0, r.p.size());
  test::drift(global, 0, global.size());
  sort_and_find(comm, r, c, r.d.first_global_index, false);
  if (comm.size() > 1) {
    EXPECT_GT(comm.sum(std::uint64_t(r.d.sent_away)), 0u) << "the step must move particles across a cut";
  }
  for (const std::uint64_t key : r.keys) EXPECT_EQ(owner_of(key, r.cuts), comm.rank());
  // No particle lost or duplicated: the ids over all ranks are 0..N-1 once each.
  Bytes mine(r.p.size() * sizeof(std::uint64_t));
  std::memcpy(mine.data(), r.p.id.data(), mine.size());
  if (comm.is_root()) {
    std::vector<std::uint64_t> ids;
    for (const Bytes& b : comm.gather_to_root(mine)) {
      const std::size_t at = ids.size();
      ids.resize(at + b.size() / sizeof(std::uint64_t));
      std::memcpy(ids.data() + at, b.data(), b.size());
    }
    ASSERT_EQ(ids.size(), kParticles);
    std::sort(ids.begin(), ids.end());
    for (std::uint64_t g = 0; g < kParticles; ++g) ASSERT_EQ(ids[g], g);
  } else {
    comm.gather_to_root(mine);
  }
  global = one_rank_order(global, r.frame);
  r.halo.insert(comm, r.p, r.keys);  // every field
  const auto second = check_halo(comm, r, global, c.skin);
  for (std::size_t i = 0; i < r.p.size(); ++i) EXPECT_EQ(r.p.extra(temperature)[i], 300.0 + double(r.p.id[i]));

  // Figures for docs/design/mpi.md: ghosts and halo (within h + skin) per particle, bytes per rank.
  std::vector<std::uint64_t> totals{first[0], first[1], second[0], insert.bytes_sent, refresh.bytes_sent, ask.bytes_sent,
                                    insert.messages};
  comm.sum(totals);
  if (comm.is_root())
    std::cout << "[figures] ranks " << comm.size() << (c.curve == spatial::CellOrder::Rows ? " rows" : " morton")
              << " skin " << c.skin / kSpacing << " spacings" << (c.scattered ? ", scattered" : "")
              << ": ghosts " << double(totals[0]) / double(kParticles)
              << " per particle (within h+skin " << double(totals[1]) / double(kParticles) << ", after the step "
              << double(totals[2]) / double(kParticles) << "); per rank: insert " << totals[3] / comm.size()
              << " B in " << double(totals[6]) / comm.size() << " messages, refresh (2 fields) "
              << totals[4] / comm.size() << " B, requests " << totals[5] / comm.size() << " B\n";
}

INSTANTIATE_TEST_SUITE_P(Frames, HaloTest,
                         ::testing::Values(Case{spatial::CellOrder::Rows, 0.0, false},
                                           Case{spatial::CellOrder::Morton, 0.0, false},
                                           Case{spatial::CellOrder::Rows, 0.3 * kSpacing, false},
                                           Case{spatial::CellOrder::Rows, 0.0, true},
                                           Case{spatial::CellOrder::Morton, 0.3 * kSpacing, true}),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return std::string(param.param.curve == spatial::CellOrder::Rows ? "Rows" : "Morton") +
                                  (param.param.skin > 0 ? "Skin" : "") + (param.param.scattered ? "Scattered" : "");
                         });

// Five particles, all on rank 0 at the start: with more ranks some own none,
// and the global tail (15 > 5) makes every rank hold all five, in order.
TEST(Halo, TheTailReachesEveryRankEvenEmptyOnes) {
  const Communicator& comm = Communicator::world();
  ParticleSet<double> p(comm.is_root() ? 5 : 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.position.x[i] = 0.1 * double(4 - i);  // reversed: the sort moves them
    p.id[i] = i;
  }
  bool fits = false;
  const spatial::KeyFrame frame = global_key_frame(comm, p, {true, 0.01, 0, spatial::CellOrder::Rows}, fits);
  ASSERT_TRUE(fits);
  std::vector<std::uint64_t> keys = keys_in_frame(frame, p);
  const std::vector<std::uint64_t> cuts = balanced_cut_keys(comm, keys, std::vector<std::uint64_t>(keys.size(), 1));
  const Distribution d = distribute_in_key_order(comm, p, keys, 0, cuts);
  Halo halo = Halo::find(comm, frame, keys, d.first_global_index, d.global_count, cuts, 15);
  halo.insert(comm, p, keys);
  ASSERT_EQ(p.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(halo.global_index()[i], i);
    EXPECT_EQ(p.id[i], 4 - i);
  }
  halo.remove(p, keys);
  EXPECT_EQ(p.size(), halo.owned_count());
  EXPECT_EQ(comm.sum(std::uint64_t(p.size())), 5u);
}

TEST(Halo, RefusesWhatItCannotPlace) {
  const Communicator& comm = Communicator::world();
  ParticleSet<double> p(3);
  std::vector<std::uint64_t> keys{3, 1, 2};
  spatial::KeyFrame f;
  f.curve = spatial::CellOrder::Rows;
  f.cells = {4, 1, 1};
  const std::vector<std::uint64_t> cuts(static_cast<std::size_t>(comm.size() - 1), 4);
  EXPECT_THROW(Halo::find(comm, f, keys, 0, 3, cuts), std::invalid_argument);  // unsorted keys
  EXPECT_THROW(Halo::find(comm, f, {}, 0, 0, std::vector<std::uint64_t>(static_cast<std::size_t>(comm.size()), 4)),
               std::invalid_argument);  // one cut too many
  keys = {1, 2, 3};
  Halo h = Halo::find(comm, f, keys, 0, 3, cuts);
  std::vector<std::uint64_t> two{1, 2};
  EXPECT_THROW(h.insert(comm, p, two), std::invalid_argument);
  EXPECT_THROW(h.refresh(comm, p, {"density"}), std::logic_error);
}

}  // namespace
}  // namespace swirl::dist
