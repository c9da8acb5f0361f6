// io::read_regular_file, the one reader of every input file (issue 17, finding 10).
#include "swirl/io/read_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "io/io_test_util.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/checkpoint.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"

namespace swirl::io {
namespace {

using namespace swirl::io::test;

TEST(ReadRegularFile, ReadsARegularFileWithinItsLimit) {
  TempDir dir;
  spit(dir / "a.txt", "12345");
  EXPECT_EQ(read_regular_file(dir / "a.txt", 5), "12345");
  const std::string e = io_error_of([&] { read_regular_file(dir / "a.txt", 4); });
  EXPECT_NE(e.find("5 bytes, more than a valid file of this kind can hold (4 bytes)"), std::string::npos) << e;
}

// A FIFO nobody writes to would block a reader forever (and, while reading a
// checkpoint, through SIGTERM): every reader refuses it at once instead.
TEST(ReadRegularFile, EveryReaderRefusesAFifoWithoutBlocking) {
  TempDir dir;
  const fs::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto refused = [](const std::string& e) { return e.find("a FIFO (named pipe); swirl reads only regular files"); };
  EXPECT_NE(refused(io_error_of([&] { read_regular_file(fifo, 100); })), std::string::npos);
  EXPECT_NE(refused(io_error_of([&] { read_text_file(fifo); })), std::string::npos);
  EXPECT_NE(refused(io_error_of([&] { read_pvd(fifo); })), std::string::npos);
  EXPECT_NE(refused(io_error_of([&] { read_vtp(fifo); })), std::string::npos);
  EXPECT_NE(refused(io_error_of([&] { read_checkpoint_header(fifo); })), std::string::npos);
  ParticleSet<double> p;
  CheckpointValues values;
  EXPECT_NE(refused(io_error_of([&] { read_checkpoint(fifo, p, values); })), std::string::npos);
}

TEST(ReadRegularFile, RefusesDirectoriesAndDevices) {
  TempDir dir;
  EXPECT_NE(io_error_of([&] { read_regular_file(dir.path(), 100); }).find("is a directory"), std::string::npos);
  EXPECT_NE(io_error_of([&] { read_regular_file("/dev/zero", 100); }).find("a character device"), std::string::npos);
  EXPECT_NE(io_error_of([&] { read_regular_file(dir / "missing", 100); }).find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace swirl::io
