// dist::RankOrder's balance (dist/rank_order.hpp), run by CTest on 1-4 ranks:
// the cuts split the solvers' cost (not the particle count), are kept while
// the imbalance stays within the threshold, and wherever they fall the ranks'
// particles in rank order are the same global order.
#include "swirl/dist/rank_order.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <vector>

#include "dist/lattice_block.hpp"

namespace swirl::dist {
namespace {

constexpr std::size_t kParticles = 4000;

// A position in [0,1)^3 for global particle g (the same on every rank).
double coordinate(std::uint64_t g, int axis) { return test::unit_hash(g, static_cast<std::uint64_t>(axis)); }

ParticleSet<double> whole_set() {
  ParticleSet<double> p(kParticles);
  for (std::size_t g = 0; g < kParticles; ++g) {
    for (int a = 0; a < 3; ++a) p.position[a][g] = coordinate(g, a);
    p.id[g] = g;
  }
  return p;
}

// The particles of the first octant (the first eighth of the Morton order,
// whatever the axes' bit order) cost 40 more: 85 % of the work.
void heavy_corner(const ParticleSet<double>& p, std::span<std::uint64_t> costs) {
  for (std::size_t i = 0; i < costs.size(); ++i)
    if (p.position.x[i] < 0.5 && p.position.y[i] < 0.5 && p.position.z[i] < 0.5) costs[i] += 40;
}

struct Balanced {
  std::vector<std::uint64_t> ids;  // every particle's id in the global order (on the root)
  std::uint64_t count = 0;         // this rank's particles
  double imbalance = 0;
};

Balanced sort_once(const Communicator& comm, bool weighted) {
  ParticleSet<double> p = whole_set();
  RankOrder<double> order(comm);
  order.set_request({true, 0.05, 0, spatial::CellOrder::Morton});
  if (weighted)
    order.set_cost_rule([&p](std::span<std::uint64_t> costs) {
      heavy_corner(p, costs);
      return true;
    });
  order.adopt(p, false);
  order.update(p, 256);
  Balanced b;
  b.count = p.size();
  b.imbalance = order.imbalance();
  Bytes mine(p.size() * sizeof(std::uint64_t));
  std::memcpy(mine.data(), p.id.data(), mine.size());
  for (const Bytes& from : comm.gather_to_root(mine)) {
    const std::size_t at = b.ids.size();
    b.ids.resize(at + from.size() / sizeof(std::uint64_t));
    std::memcpy(b.ids.data() + at, from.data(), from.size());
  }
  return b;
}

TEST(RankOrder, CutsBalanceTheSolversCostAndChangeNoOrder) {
  const Communicator& comm = Communicator::world();
  const Balanced by_count = sort_once(comm, false);
  const Balanced by_cost = sort_once(comm, true);
  if (comm.is_root()) {
    EXPECT_EQ(by_cost.ids, by_count.ids) << "where the cuts fall must not change the global order";
    ASSERT_EQ(by_cost.ids.size(), kParticles);
  }
  std::printf("rank %d: %llu particles by count, %llu by cost; imbalance of the cost cuts %.3f\n", comm.rank(),
              static_cast<unsigned long long>(by_count.count), static_cast<unsigned long long>(by_cost.count),
              by_cost.imbalance);
  if (comm.size() > 1) {
    // 64 keys of 0.05-cells hold ~60 particles each: a cut cannot split one,
    // so the balance is within about one key's cost of even.
    EXPECT_LT(by_cost.imbalance, 1.15);
    double fewest[1] = {double(by_cost.count)}, most[1] = {double(by_cost.count)};
    comm.min(fewest);
    comm.max(most);
    EXPECT_GT(most[0], 2.0 * fewest[0]) << "the heavy corner's ranks hold fewer particles";
  } else {
    EXPECT_EQ(by_cost.imbalance, 1.0);
  }
}

TEST(RankOrder, CutsAreKeptWhileTheImbalanceIsWithinTheThreshold) {
  const Communicator& comm = Communicator::world();
  for (const double threshold : {1.0, 1e9}) {
    ParticleSet<double> p = whole_set();
    RankOrder<double> order(comm);
    order.set_request({true, 0.05, 0, spatial::CellOrder::Morton});
    order.set_rebalance_threshold(threshold);
    bool weighted = false;  // from the second sort on, the corner is heavy
    order.set_cost_rule([&](std::span<std::uint64_t> costs) {
      if (weighted) heavy_corner(p, costs);
      return true;
    });
    order.adopt(p, false);
    order.update(p, 256);
    EXPECT_EQ(order.rebalances(), 1u) << "the first sort always balances";
    weighted = true;
    for (std::size_t i = 0; i < p.size(); ++i) p.position.y[i] *= 0.999;  // moved a little: a new sort
    order.update(p, 256);
    if (comm.size() > 1 && threshold == 1.0) {
      EXPECT_EQ(order.rebalances(), 2u) << "imbalanced: new cuts";
      EXPECT_LT(order.imbalance(), 1.15);
    } else if (comm.size() > 1) {
      EXPECT_EQ(order.rebalances(), 1u) << "within the threshold: the cuts kept";
      EXPECT_GT(order.imbalance(), 1.5) << "the kept cuts split the count, not the cost";
    }
    EXPECT_EQ(comm.sum(std::uint64_t(p.size())), kParticles);
  }
  RankOrder<double> order(comm);
  EXPECT_THROW(order.set_rebalance_threshold(0.9), std::invalid_argument);
}

// Block time steps' sub-steps measure no whole step's work: a cost rule that
// says so keeps the cuts even at threshold 1 and with a heavy corner, and the
// reported imbalance stays the last measured; the next measured sort
// rebalances.
TEST(RankOrder, CutsAreKeptWhenTheLastEvaluationMeasuredNoWholeStep) {
  const Communicator& comm = Communicator::world();
  ParticleSet<double> p = whole_set();
  RankOrder<double> order(comm);
  order.set_request({true, 0.05, 0, spatial::CellOrder::Morton});
  order.set_rebalance_threshold(1.0);
  bool measured = true, heavy = false;
  order.set_cost_rule([&](std::span<std::uint64_t> costs) {
    if (heavy) heavy_corner(p, costs);
    return measured;
  });
  order.adopt(p, false);
  order.update(p, 256);
  ASSERT_EQ(order.rebalances(), 1u);
  const double first = order.imbalance();
  const std::vector<std::uint64_t> cuts(order.cut_keys().begin(), order.cut_keys().end());
  measured = false, heavy = true;
  for (std::size_t i = 0; i < p.size(); ++i) p.position.y[i] *= 0.999;
  order.update(p, 256);
  EXPECT_EQ(order.rebalances(), 1u) << "not measured: the cuts kept";
  EXPECT_EQ(order.imbalance(), first) << "not measured: the last measured imbalance";
  EXPECT_EQ(std::vector<std::uint64_t>(order.cut_keys().begin(), order.cut_keys().end()), cuts);
  EXPECT_EQ(comm.sum(std::uint64_t(p.size())), kParticles);
  measured = true;
  for (std::size_t i = 0; i < p.size(); ++i) p.position.y[i] *= 0.999;
  order.update(p, 256);
  if (comm.size() > 1) {
    EXPECT_EQ(order.rebalances(), 2u) << "measured and imbalanced: new cuts";
    EXPECT_LT(order.imbalance(), 1.15);
  }
}

}  // namespace
}  // namespace swirl::dist
