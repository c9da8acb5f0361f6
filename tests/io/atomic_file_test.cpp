#include "swirl/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <thread>

#include "io/io_test_util.hpp"

namespace swirl::io {
namespace {

using namespace swirl::io::test;

class AtomicFileTest : public ::testing::Test {
 protected:
  TempDir dir;
};

TEST_F(AtomicFileTest, WritesAndReplacesContent) {
  const auto path = dir / "out.txt";
  write_file_atomic(path, "first");
  EXPECT_EQ(slurp(path), "first");
  write_file_atomic(path, "second, and longer", /*sync=*/true);
  EXPECT_EQ(slurp(path), "second, and longer");
  write_file_atomic(path, "");
  EXPECT_TRUE(fs::exists(path));
  EXPECT_EQ(slurp(path), "");
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"out.txt"});
}

TEST_F(AtomicFileTest, WritesBinaryContentExactly) {
  std::string bytes(3 << 20, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 131) >> 3);
  const auto path = dir / "blob.bin";
  write_file_atomic(path, bytes, true);
  EXPECT_TRUE(slurp(path) == bytes);
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"blob.bin"});
}

TEST_F(AtomicFileTest, ConcurrentWritersLeaveOneCompleteVersion) {
  const auto path = dir / "shared.txt";
  std::vector<std::thread> threads;
  for (int t = 0; t < 6; ++t)
    threads.emplace_back([&, t] {
      for (int k = 0; k < 30; ++k) write_file_atomic(path, std::string(64 * 1024, static_cast<char>('a' + t)));
    });
  for (auto& th : threads) th.join();
  const std::string content = slurp(path);
  ASSERT_EQ(content.size(), 64u * 1024u);
  EXPECT_EQ(content.find_first_not_of(content[0]), std::string::npos);
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"shared.txt"});
}

TEST_F(AtomicFileTest, FailureNamesPathAndReason) {
  spit(dir / "blocker", "keep me");
  const auto path = dir / "blocker" / "out.txt";
  const std::string message = io_error_of([&] { write_file_atomic(path, "data"); });
  EXPECT_TRUE(message.starts_with(path.string() + ": ")) << message;
  EXPECT_NE(message.find("Not a directory"), std::string::npos) << message;
  EXPECT_EQ(slurp(dir / "blocker"), "keep me");
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"blocker"});
}

TEST_F(AtomicFileTest, FailedRenameRemovesTheTemporaryFile) {
  // A non-empty directory where the file should go: everything succeeds up to the rename.
  fs::create_directory(dir / "target");
  spit(dir / "target" / "keep", "kept");
  const std::string message = io_error_of([&] { write_file_atomic(dir / "target", "data", true); });
  EXPECT_TRUE(message.starts_with((dir / "target").string() + ": ")) << message;
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"target"});
  EXPECT_EQ(slurp(dir / "target" / "keep"), "kept");
}

// RLIMIT_FSIZE makes write() fail with EFBIG even for root, so this exercises
// the failed-write path (temporary file removed, target untouched) everywhere.
TEST_F(AtomicFileTest, FailedWriteKeepsTheExistingFile) {
  const auto path = dir / "out.txt";
  write_file_atomic(path, "original");

  rlimit old_limit{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  rlimit small = old_limit;
  small.rlim_cur = 4096;
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string message = io_error_of([&] { write_file_atomic(path, std::string(1 << 20, 'x')); });
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);

  EXPECT_TRUE(message.starts_with(path.string() + ": ")) << message;
  EXPECT_NE(message.find("too large"), std::string::npos) << message;
  EXPECT_EQ(slurp(path), "original");
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"out.txt"});
}

TEST_F(AtomicFileTest, ReadOnlyDirectoryKeepsTheExistingFile) {
  if (::geteuid() == 0)
    GTEST_SKIP() << "running as root, which ignores permission bits; FailedWriteKeepsTheExistingFile and "
                    "FailureNamesPathAndReason cover the failure paths";
  const auto path = dir / "out.txt";
  write_file_atomic(path, "original");
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  const std::string message = io_error_of([&] { write_file_atomic(path, "replacement"); });
  fs::permissions(dir.path(), fs::perms::owner_all);
  EXPECT_TRUE(message.starts_with(path.string() + ": ")) << message;
  EXPECT_NE(message.find("Permission denied"), std::string::npos) << message;
  EXPECT_EQ(slurp(path), "original");
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"out.txt"});
}

TEST_F(AtomicFileTest, EnsureWritableDirectoryCreatesMissingDirectories) {
  const auto nested = dir / "a" / "b" / "c";
  ensure_writable_directory(nested);
  EXPECT_TRUE(fs::is_directory(nested));
  EXPECT_TRUE(fs::is_empty(nested));  // the probe file is gone
  ensure_writable_directory(nested);  // existing is fine too
  EXPECT_TRUE(fs::is_empty(nested));
}

TEST_F(AtomicFileTest, EnsureWritableDirectoryRejectsFiles) {
  spit(dir / "file", "x");
  for (const auto& bad : {dir / "file", dir / "file" / "sub"}) {
    const std::string message = io_error_of([&] { ensure_writable_directory(bad); });
    EXPECT_TRUE(message.starts_with(bad.string() + ": ")) << message;
  }
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"file"});
}

TEST_F(AtomicFileTest, EnsureWritableDirectoryRejectsReadOnlyDirectory) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root, which ignores permission bits";
  const auto ro = dir / "ro";
  fs::create_directory(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string message = io_error_of([&] { ensure_writable_directory(ro); });
  fs::permissions(ro, fs::perms::owner_all);
  EXPECT_TRUE(message.starts_with(ro.string() + ": ")) << message;
  EXPECT_NE(message.find("Permission denied"), std::string::npos) << message;
}

}  // namespace
}  // namespace swirl::io
