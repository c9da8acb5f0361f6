// Test helpers of the writers that the ranks use together
// (snapshot_on_ranks_test, checkpoint_on_ranks_test): one temporary folder
// for every rank, the cuts of a set into the ranks' shares, and the checks
// after a write that must fail on every rank and keep the file it replaces.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "io/io_test_util.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io::test {

// One folder for every rank: rank 0 makes it and says where.
class SharedDir {
 public:
  explicit SharedDir(const dist::Communicator& comm) : comm_(comm) {
    if (comm.is_root()) own_ = std::make_unique<TempDir>();
    path_ = comm.first_text(comm.is_root() ? own_->path().string() : std::string());
  }
  ~SharedDir() { comm_.barrier(); }  // every rank done with it before rank 0 removes it
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  const dist::Communicator& comm_;
  std::unique_ptr<TempDir> own_;
  std::filesystem::path path_;
};

// Rank r's share [cut[r], cut[r+1]) of n particles by `pattern`: 0 even, 1
// growing shares (r² steps), 2 all on the last rank (the others empty).
inline std::vector<std::size_t> rank_cuts(std::size_t n, std::size_t ranks, int pattern) {
  std::vector<std::size_t> cut(ranks + 1, n);
  for (std::size_t r = 0; r < ranks; ++r) cut[r] = pattern == 0 ? n * r / ranks : pattern == 1 ? n * r * r / (ranks * ranks) : 0;
  return cut;
}

// The regular files in `dir` (a temporary file left behind shows here).
inline std::size_t regular_files(const std::filesystem::path& dir) {
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  return files;
}

inline constexpr std::string_view kOldFile = "the old file";

// Collective: rank 0 puts kOldFile at dir/name for a write to replace.
inline void place_old_file(const dist::Communicator& comm, const SharedDir& dir, const std::string& name) {
  if (comm.is_root()) write_file_atomic(dir / name, kOldFile);
  comm.barrier();
}

// Collective, after a write over place_old_file's that failed with `said`:
// every rank has the same words, and the folder holds the old file alone
// (unchanged, no temporary file beside it).
inline void expect_failed_everywhere_and_kept(const dist::Communicator& comm, const SharedDir& dir,
                                              const std::string& said, const std::string& name) {
  EXPECT_NE(said.rfind("(n", 0), 0u) << said;  // io_error_of's "(no exception)" or "(not an IoError) ..."
  EXPECT_EQ(comm.first_text(comm.is_root() ? said : std::string()), said);
  if (comm.is_root()) {
    EXPECT_EQ(slurp(dir / name), kOldFile);
    EXPECT_EQ(regular_files(dir.path()), 1u) << "a temporary file was left";
  }
  comm.barrier();
}

}  // namespace swirl::io::test
