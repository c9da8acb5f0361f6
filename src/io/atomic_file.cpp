#include "swirl/io/atomic_file.hpp"

#include "swirl/io/read_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <string>
#include <system_error>

#include <fmt/format.h>

namespace swirl::io {
namespace {

namespace fs = std::filesystem;

// Distinguishes temporary names of concurrent writers within one process; the
// pid does so across processes.
std::atomic<unsigned long> g_counter{0};

std::string errno_text(int err) { return std::generic_category().message(err); }

[[noreturn]] void fail(const fs::path& path, std::string_view what, int err) {
  throw IoError(fmt::format("{}: {}: {}", path.string(), what, errno_text(err)));
}

fs::path unique_sibling(const fs::path& path, std::string_view tag) {
  return path.parent_path() /
         fmt::format(".{}.{}.{}.{}", path.filename().string(), tag, ::getpid(), g_counter.fetch_add(1));
}

void sync_directory(const fs::path& path) {
  fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail(path, "written, but its directory cannot be opened to sync it", errno);
  int rc = ::fsync(fd);
  int err = errno;
  ::close(fd);
  // Some file systems cannot fsync a directory at all (EINVAL); the data are
  // then as durable as that file system allows.
  if (rc != 0 && err != EINVAL) fail(path, "written, but syncing its directory failed", err);
}

}  // namespace

namespace detail {
TempFile::~TempFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!released_) ::unlink(path_.c_str());
}
int TempFile::open() { return fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666); }
int TempFile::close() {
  const int fd = fd_;
  fd_ = -1;  // close() releases the descriptor even when it reports an error
  return ::close(fd);
}
}  // namespace detail

AtomicFileWriter::AtomicFileWriter(const fs::path& path) : path_(path), temporary_(temporary_sibling(path)) {
  if (temporary_.open() < 0) fail(path, fmt::format("cannot create temporary file {}", temporary_.path().string()), errno);
}

void AtomicFileWriter::append(std::string_view bytes) {
  if (temporary_.fd() < 0) throw IoError(fmt::format("{}: written after it was committed or failed", path_.string()));
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    ssize_t n = ::write(temporary_.fd(), p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      temporary_.close();
      fail(path_, "write failed", err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

void AtomicFileWriter::commit(bool sync) {
  if (temporary_.fd() < 0) throw IoError(fmt::format("{}: committed twice or after a failed write", path_.string()));
  if (sync && ::fsync(temporary_.fd()) != 0) fail(path_, "fsync failed", errno);
  // Delayed-allocation file systems may report ENOSPC or EIO only here.
  if (temporary_.close() != 0) fail(path_, "close failed", errno);
  if (::rename(temporary_.path().c_str(), path_.c_str()) != 0)
    fail(path_, "cannot rename the temporary file over it", errno);
  temporary_.release();
  if (sync) sync_directory(path_);
}

void write_file_atomic(const fs::path& path, std::string_view bytes, bool sync) {
  AtomicFileWriter file(path);
  file.append(bytes);
  file.commit(sync);
}

fs::path temporary_sibling(const fs::path& path) {
  if (path.filename().empty()) throw IoError(fmt::format("{}: not a file name", path.string()));
  return unique_sibling(path, "tmp");
}

void publish_file_atomic(const fs::path& temporary, const fs::path& path) {
  detail::TempFile tmp(temporary);  // removed if the rename fails
  if (::rename(temporary.c_str(), path.c_str()) != 0) fail(path, "cannot rename the temporary file over it", errno);
  tmp.release();
}

void ensure_writable_directory(const fs::path& dir, std::uintmax_t bytes_needed) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create directory: {}", dir.string(), ec.message()));

  // Permission bits do not tell the whole story (read-only mounts, ACLs, root),
  // so the only reliable test is to create a file.
  detail::TempFile probe(unique_sibling(dir / "probe", "writable"));
  if (probe.open() < 0) fail(dir, "directory is not writable", errno);
  if (probe.close() != 0) fail(dir, "directory is not writable (close failed)", errno);
  const auto space = fs::space(dir, ec);
  if (!ec && space.available < bytes_needed)
    throw IoError(fmt::format("{}: the disk is full: {} bytes free, the run needs about {} for its first outputs",
                              dir.string(), space.available, bytes_needed));
}

void ensure_writable_file(const fs::path& path) {
  if (path.filename().empty() || path.filename() == "." || path.filename() == "..")
    throw IoError(fmt::format("{}: not a file name", path.string()));
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (fs::exists(st) && !fs::is_regular_file(st))
    throw IoError(fmt::format("{}: exists and is not a regular file", path.string()));
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(dir, ec))
    throw IoError(fmt::format("{}: cannot be written: the folder {} does not exist", path.string(), dir.string()));
  detail::TempFile probe(unique_sibling(path, "probe"));
  if (probe.open() < 0) fail(path, "cannot be written", errno);
  if (probe.close() != 0) fail(path, "cannot be written (close failed)", errno);
}

std::string read_text_file(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  return read_regular_file(path, max_bytes);
}

}  // namespace swirl::io
