// HDF5 snapshots written by the ranks of a run together
// (dist/snapshot_on_ranks.hpp over parallel HDF5; issue 19 item 6), on 1-4 ranks: the file is byte for byte the
// one write_snapshot() writes for the whole set on one process, for any cut of
// the set into ranks (uneven, ranks without particles, cuts inside the chunks of
// the datasets) and for a selection of rows (a frame series of one particle
// kind); a write that fails fails on every rank with the same words and leaves
// the file that was there.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "dist/shared_dir.hpp"
#include "io/io_test_util.hpp"
#include "swirl/dist/snapshot_on_ranks.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/write_faults.hpp"

namespace swirl::io {
namespace {

using test::SharedDir;

template <class Real>
class SnapshotOnRanks : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SnapshotOnRanks, Precisions);

TYPED_TEST(SnapshotOnRanks, TheRanksWriteTheOneProcessBytes) {
  using Real = TypeParam;
  const dist::Communicator& comm = dist::Communicator::world();
  const auto ranks = std::size_t(comm.size()), r = std::size_t(comm.rank());
  SharedDir dir(comm);
  // Three chunks (65 536 rows each): cuts fall inside chunks, a rank holds a
  // whole chunk or all of them.
  const std::size_t n = 140001;
  const auto whole = test::make_particles<Real>(n);
  SnapshotInfo info;
  info.time = 0.75;
  info.type = PartType::Gas;
  info.box_size = 2;
  if (comm.is_root()) write_snapshot(dir / "one.h5", whole, info);
  // Every third particle: a series of one kind.
  std::vector<std::size_t> every_third;
  for (std::size_t i = 0; i < n; i += 3) every_third.push_back(i);
  if (comm.is_root()) write_snapshot(dir / "one_rows.h5", whole, info, std::span<const std::size_t>(every_third));
  int compared = 0;
  for (int pattern = 0; pattern < 3; ++pattern) {
    const auto cut = test::rank_cuts(n, ranks, pattern);
    std::vector<std::size_t> mine(cut[r + 1] - cut[r]);
    std::iota(mine.begin(), mine.end(), cut[r]);
    const auto own = whole.subset(mine);
    const std::string name = "ranks_" + std::to_string(pattern) + ".h5";
    const SnapshotLayout layout = dist::write_snapshot_on_ranks(comm, dir / name, own, info);
    EXPECT_EQ(layout.count, n);
    // The same selection on ranks: the rows of every third particle that this rank holds.
    std::vector<std::size_t> rows;
    for (std::size_t i = 0; i < own.size(); ++i)
      if ((cut[r] + i) % 3 == 0) rows.push_back(i);
    const std::string rows_name = "ranks_rows_" + std::to_string(pattern) + ".h5";
    dist::write_snapshot_on_ranks(comm, dir / rows_name, own, info, std::span<const std::size_t>(rows));
    comm.barrier();
    if (comm.is_root()) {
      EXPECT_EQ(test::slurp(dir / name), test::slurp(dir / "one.h5")) << "cut pattern " << pattern;
      EXPECT_EQ(test::slurp(dir / rows_name), test::slurp(dir / "one_rows.h5")) << "cut pattern " << pattern;
      compared += 2;
    }
  }
  if (comm.is_root()) {
    EXPECT_EQ(compared, 6);
    // The comparison can fail: another state gives other bytes, and the file reads back.
    auto other = whole;
    other.velocity.y[n - 2] += Real(1);
    write_snapshot(dir / "other.h5", other, info);
    EXPECT_NE(test::slurp(dir / "other.h5"), test::slurp(dir / "one.h5"));
    const SnapshotFile s = read_snapshot(dir / "ranks_1.h5");
    EXPECT_EQ(s.count, n);
    EXPECT_EQ(s.ids, std::vector<std::uint64_t>(whole.id.begin(), whole.id.end()));
  }
}

// One rank's write fails inside the collective sequence (its second dataset,
// the velocities, as a full disk would refuse it), the others' succeed: every
// rank still ends the file's collective calls (none waits for the failed rank:
// without that this test hangs until ctest's timeout) and reports the
// failed rank's words; the old file stays, no temporary file is left.
TEST(SnapshotOnRanks, AWriteFailingOnOneRankAloneFailsOnEveryRankWithoutAHang) {
  const dist::Communicator& comm = dist::Communicator::world();
  SharedDir dir(comm);
  const auto p = test::make_particles<double>(1000);
  test::place_old_file(comm, dir, "kept.h5");
  const bool failing = comm.rank() == comm.size() - 1;
  if (failing) testing::fail_snapshot_dataset_write(2);
  const std::string said =
      test::io_error_of([&] { dist::write_snapshot_on_ranks(comm, dir / "kept.h5", p, SnapshotInfo{}); });
  testing::fail_snapshot_dataset_write(0);
  EXPECT_NE(said.find("kept.h5"), std::string::npos) << said;
  EXPECT_NE(said.find("Velocities"), std::string::npos) << said;
  test::expect_failed_everywhere_and_kept(comm, dir, said, "kept.h5");
  // The next write succeeds.
  dist::write_snapshot_on_ranks(comm, dir / "kept.h5", p, SnapshotInfo{});
  if (comm.is_root()) {
    EXPECT_EQ(read_snapshot(dir / "kept.h5").count, 1000u * std::size_t(comm.size()));
  }
}

TEST(SnapshotOnRanks, AFailedWriteFailsOnEveryRankAndKeepsTheOldFile) {
  const dist::Communicator& comm = dist::Communicator::world();
  SharedDir dir(comm);
  const auto p = test::make_particles<double>(100);
  test::place_old_file(comm, dir, "kept.h5");
  // A folder that does not exist: the file cannot be created on any rank.
  const std::string said =
      test::io_error_of([&] { dist::write_snapshot_on_ranks(comm, dir / "missing" / "kept.h5", p, SnapshotInfo{}); });
  EXPECT_NE(said.find("missing"), std::string::npos) << said;
  // Every rank has the same words; a written file replaces the old one only whole.
  test::expect_failed_everywhere_and_kept(comm, dir, said, "kept.h5");
  dist::write_snapshot_on_ranks(comm, dir / "kept.h5", p, SnapshotInfo{});
  if (comm.is_root()) {
    EXPECT_EQ(read_snapshot(dir / "kept.h5").count, 100u * std::size_t(comm.size()));
    // No temporary file is left beside it.
    EXPECT_EQ(test::regular_files(dir.path()), 1u);
  }
}

}  // namespace
}  // namespace swirl::io
