// The communicator's collectives on 1-4 ranks (run by CTest under mpirun).
#include "swirl/dist/communicator.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace swirl::dist {
namespace {

TEST(Communicator, RanksAndExactReductions) {
  const Communicator& comm = Communicator::world();
  ASSERT_GE(comm.size(), 1);
  ASSERT_LT(comm.rank(), comm.size());
  const auto r = static_cast<std::uint64_t>(comm.rank());
  const auto n = static_cast<std::uint64_t>(comm.size());
  EXPECT_EQ(comm.sum(r + 1), n * (n + 1) / 2);
  EXPECT_EQ(comm.exclusive_prefix_sum(r + 1), r * (r + 1) / 2);
  std::vector<double> low{static_cast<double>(comm.rank()), -static_cast<double>(comm.rank())};
  std::vector<double> high = low;
  comm.min(low);
  comm.max(high);
  EXPECT_EQ(low[0], 0.0);
  EXPECT_EQ(low[1], -static_cast<double>(n - 1));
  EXPECT_EQ(high[0], static_cast<double>(n - 1));
  EXPECT_EQ(high[1], 0.0);
  const std::vector<std::uint64_t> all = comm.all_gather(10 * r);
  ASSERT_EQ(all.size(), n);
  for (std::uint64_t s = 0; s < n; ++s) EXPECT_EQ(all[s], 10 * s);
}

TEST(Communicator, AllToAllDeliversEachBufferToItsRank) {
  const Communicator& comm = Communicator::world();
  const auto ranks = static_cast<std::size_t>(comm.size());
  // Rank s sends s+d+1 bytes of value 16·s + d to rank d (some empty: none here).
  std::vector<Bytes> send(ranks);
  for (std::size_t d = 0; d < ranks; ++d)
    send[d].assign(static_cast<std::size_t>(comm.rank()) + d + 1, std::byte(16 * comm.rank() + static_cast<int>(d)));
  const std::vector<Bytes> got = comm.all_to_all(send);
  ASSERT_EQ(got.size(), ranks);
  for (std::size_t s = 0; s < ranks; ++s) {
    ASSERT_EQ(got[s].size(), s + static_cast<std::size_t>(comm.rank()) + 1);
    for (std::byte b : got[s]) EXPECT_EQ(b, std::byte(16 * static_cast<int>(s) + comm.rank()));
  }
}

TEST(Communicator, AllGatherGivesEveryRankEveryRanksBytesInRankOrder) {
  const Communicator& comm = Communicator::world();
  // Rank s contributes 3·s bytes of value s + 1 (rank 0: none).
  const Bytes mine(3 * static_cast<std::size_t>(comm.rank()), std::byte(comm.rank() + 1));
  const std::vector<Bytes> all = comm.all_gather(mine);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(comm.size()));
  for (std::size_t s = 0; s < all.size(); ++s) EXPECT_EQ(all[s], Bytes(3 * s, std::byte(s + 1)));
}

TEST(Communicator, FirstTextIsTheLowestRankWithText) {
  const Communicator& comm = Communicator::world();
  // Nobody has text: empty everywhere.
  EXPECT_EQ(comm.first_text(""), "");
  // Every rank from 1 on (or rank 0 alone on one rank) has text: the lowest one's.
  const int speaker = comm.size() > 1 ? 1 : 0;
  const std::string mine = comm.rank() >= speaker ? "rank " + std::to_string(comm.rank()) : std::string();
  EXPECT_EQ(comm.first_text(mine), "rank " + std::to_string(speaker));
  // Only the last rank speaks.
  EXPECT_EQ(comm.first_text(comm.rank() == comm.size() - 1 ? "last" : ""), "last");
}

TEST(Communicator, GatherToRootKeepsRankOrder) {
  const Communicator& comm = Communicator::world();
  Bytes mine(static_cast<std::size_t>(comm.rank()), std::byte(comm.rank()));
  const std::vector<Bytes> all = comm.gather_to_root(mine);
  if (!comm.is_root()) {
    EXPECT_TRUE(all.empty());
    return;
  }
  ASSERT_EQ(all.size(), static_cast<std::size_t>(comm.size()));
  for (std::size_t s = 0; s < all.size(); ++s) {
    EXPECT_EQ(all[s], Bytes(s, std::byte(s)));
  }
}

// The traffic counters: each operation's logical messages and bytes, exact
// (one rank moves nothing).
TEST(Communicator, TrafficCountsEachOperationsPayloads) {
  const Communicator& comm = Communicator::world();
  const auto n = static_cast<std::uint64_t>(comm.size()), r = static_cast<std::uint64_t>(comm.rank());
  const std::uint64_t others = n - 1;
  auto measure = [&](auto&& operation) {
    const Traffic before = comm.traffic();
    operation();
    return comm.traffic() - before;
  };
  auto expect = [&](const Traffic& t, std::uint64_t collectives, std::uint64_t messages, std::uint64_t sent,
                    std::uint64_t received, const char* what) {
    SCOPED_TRACE(what);
    if (n == 1) collectives = messages = sent = received = 0;
    EXPECT_EQ(t.collectives, collectives);
    EXPECT_EQ(t.messages, messages);
    EXPECT_EQ(t.bytes_sent, sent);
    EXPECT_EQ(t.bytes_received, received);
  };
  std::vector<std::uint64_t> three(3, r);
  expect(measure([&] { comm.sum(three); }), 1, 1, 24, 24, "a sum of three");
  expect(measure([&] { comm.all_gather(r); }), 1, others, 8 * others, 8 * others, "an all-gather of one value");
  // Rank s sends s + d bytes to rank d: to itself and to rank 0 from rank 0 nothing.
  std::vector<Bytes> send(n);
  for (std::uint64_t d = 0; d < n; ++d) send[d].assign(r + d, std::byte(1));
  std::uint64_t messages = 0, sent = 0, received = 0;
  for (std::uint64_t d = 0; d < n; ++d)
    if (d != r) messages += r + d > 0 ? 1 : 0, sent += r + d, received += d + r;
  expect(measure([&] { comm.all_to_all(send); }), 1, messages, sent, received, "an all-to-all");
  // Rank s contributes 2·s bytes.
  std::uint64_t everyone = 0;
  for (std::uint64_t s = 0; s < n; ++s) everyone += 2 * s;
  expect(measure([&] { comm.all_gather(Bytes(2 * r, std::byte(0))); }), 1, others, 2 * r * others, everyone - 2 * r,
         "an all-gather of bytes");
  expect(measure([&] { comm.gather_to_root(Bytes(2 * r, std::byte(0))); }), 1, comm.is_root() ? 0 : 1,
         comm.is_root() ? 0 : 2 * r, comm.is_root() ? everyone : 0, "a gather to rank 0");
  expect(measure([&] { comm.barrier(); }), 1, 0, 0, 0, "a barrier");
}

}  // namespace
}  // namespace swirl::dist
