// Checkpoints of a run on ranks (dist/checkpoint_on_ranks.hpp; issue 19 item
// 6), on 1-4 ranks: rank 0 writes while the ranks hand it one array at a
// time, and the file is byte for byte the one io::write_checkpoint() writes
// for the whole set on one process, for any cut of the set into ranks
// (uneven, ranks without particles); a write that fails on rank 0 part way
// fails on every rank with its words, leaves no rank waiting and keeps the
// file that was there.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "dist/shared_dir.hpp"
#include "io/io_test_util.hpp"
#include "swirl/dist/checkpoint_on_ranks.hpp"
#include "swirl/io/checkpoint.hpp"
#include "swirl/io/write_faults.hpp"

namespace swirl::io {
namespace {

using test::SharedDir;

const CheckpointValues kValues{{"clock.previous_dt", 0.125}, {"frames.next", 3.0}};

template <class Real>
class CheckpointOnRanks : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CheckpointOnRanks, Precisions);

TYPED_TEST(CheckpointOnRanks, TheRanksHandRankZeroTheOneProcessBytes) {
  using Real = TypeParam;
  const dist::Communicator& comm = dist::Communicator::world();
  const auto ranks = std::size_t(comm.size()), r = std::size_t(comm.rank());
  SharedDir dir(comm);
  const std::size_t n = 10007;
  const auto whole = test::make_particles<Real>(n);
  const CheckpointHeader header{sizeof(Real), n, 0x5eed, 42, 0.5};
  if (comm.is_root()) write_checkpoint(dir / "one.swc", whole, header, kValues);
  int compared = 0;
  for (int pattern = 0; pattern < 3; ++pattern) {
    const auto cut = test::rank_cuts(n, ranks, pattern);
    std::vector<std::size_t> mine(cut[r + 1] - cut[r]);
    std::iota(mine.begin(), mine.end(), cut[r]);
    const auto own = whole.subset(mine);
    const std::string name = "ranks_" + std::to_string(pattern) + ".swc";
    // The header's count is the ranks' total, whatever a rank passes.
    dist::write_checkpoint_on_ranks(comm, dir / name, own, {sizeof(Real), own.size(), 0x5eed, 42, 0.5}, kValues);
    comm.barrier();
    if (comm.is_root()) {
      EXPECT_EQ(test::slurp(dir / name), test::slurp(dir / "one.swc")) << "cut pattern " << pattern;
      ++compared;
    }
  }
  if (comm.is_root()) {
    EXPECT_EQ(compared, 3);
    // The comparison can fail: another state gives other bytes; the file reads back.
    auto other = whole;
    other.velocity.z[n - 1] += Real(1);
    write_checkpoint(dir / "other.swc", other, header, kValues);
    EXPECT_NE(test::slurp(dir / "other.swc"), test::slurp(dir / "one.swc"));
    ParticleSet<Real> back;
    CheckpointValues values;
    const CheckpointHeader h = read_checkpoint(dir / "ranks_1.swc", back, values);
    EXPECT_EQ(h.particles, n);
    EXPECT_EQ(values, kValues);
    EXPECT_EQ(std::vector<std::uint64_t>(back.id.begin(), back.id.end()),
              std::vector<std::uint64_t>(whole.id.begin(), whole.id.end()));
  }
}

// Rank 0's file refuses the third array part way (as a full disk would): every
// rank still hands its arrays (none waits: without that this test hangs until
// ctest's timeout) and reports rank 0's words; the old file stays, no
// temporary file is left, and the next checkpoint is written.
TEST(CheckpointOnRanks, AWriteFailingOnRankZeroFailsOnEveryRankWithoutAHang) {
  const dist::Communicator& comm = dist::Communicator::world();
  SharedDir dir(comm);
  const auto p = test::make_particles<double>(500);
  const CheckpointHeader header{8, 0, 1, 7, 0.25};
  test::place_old_file(comm, dir, "kept.swc");
  // Rank 0 appends every rank's share of each array in turn: its 3rd append
  // is a share of the first or the second array, whatever the rank count.
  if (comm.is_root()) testing::fail_checkpoint_append(3);
  const std::string said =
      test::io_error_of([&] { dist::write_checkpoint_on_ranks(comm, dir / "kept.swc", p, header, kValues); });
  testing::fail_checkpoint_append(0);
  EXPECT_NE(said.find("kept.swc"), std::string::npos) << said;
  EXPECT_NE(said.find("no space left"), std::string::npos) << said;
  test::expect_failed_everywhere_and_kept(comm, dir, said, "kept.swc");
  dist::write_checkpoint_on_ranks(comm, dir / "kept.swc", p, header, kValues);
  if (comm.is_root()) {
    ParticleSet<double> back;
    CheckpointValues values;
    EXPECT_EQ(read_checkpoint(dir / "kept.swc", back, values).particles, 500u * std::size_t(comm.size()));
    EXPECT_EQ(test::regular_files(dir.path()), 1u);
  }
}

// A folder that does not exist: rank 0 cannot open the file, every rank says so at once.
TEST(CheckpointOnRanks, AFileRankZeroCannotOpenFailsOnEveryRank) {
  const dist::Communicator& comm = dist::Communicator::world();
  SharedDir dir(comm);
  const auto p = test::make_particles<float>(50);
  const std::string said = test::io_error_of(
      [&] { dist::write_checkpoint_on_ranks(comm, dir / "missing" / "c.swc", p, {4, 0, 1, 1, 0.0}, kValues); });
  EXPECT_NE(said.find("missing"), std::string::npos) << said;
  EXPECT_EQ(comm.first_text(comm.is_root() ? said : std::string()), said);
}

}  // namespace
}  // namespace swirl::io
