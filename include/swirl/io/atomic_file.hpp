// Writing files so that a crash never leaves a half-written one: the bytes go
// to a temporary file in the same directory, which is then renamed over the
// target (rename is atomic within one file system).
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace swirl::io {

// A file could not be read or written. what() names the file and the reason.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Writes `bytes` to `path` atomically. With `sync`, the data are fsync'ed
// before the rename and the directory after it, so they survive a power cut.
// On failure the temporary file is removed, `path` is untouched and IoError is
// thrown.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes, bool sync = false);

// The same for a file written piece by piece (a checkpoint streamed from the
// ranks, io/checkpoint.hpp), so that its bytes never need to be in memory at
// once: append() writes to the temporary file, commit() publishes it as
// write_file_atomic() does. Destroyed without commit() (an exception, a
// failed append), it removes the temporary file and `path` stays as it was.
// Every failure throws IoError naming `path`.
namespace detail {
// Owns a temporary file, its descriptor and its name, until release(): every
// early exit (a throw) closes the descriptor and removes the file.
class TempFile {
 public:
  explicit TempFile(std::filesystem::path path) : path_(std::move(path)) {}
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile();

  int open();   // creates it (never an existing file): the descriptor, or −1 with errno
  int close();  // 0, or −1 with errno; the descriptor is released either way
  void release() { released_ = true; }
  int fd() const { return fd_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  bool released_ = false;
};
}  // namespace detail

class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(const std::filesystem::path& path);

  void append(std::string_view bytes);
  void commit(bool sync);
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  detail::TempFile temporary_;  // its descriptor is closed after commit() or a failed write
};

// The same for a file that something else fills (the ranks of a parallel
// HDF5 write, dist/snapshot_on_ranks.hpp): temporary_sibling() names a
// temporary file beside `path`, unique to this process; once it is complete,
// publish_file_atomic() renames it over `path` (not synced: frames are not).
// On failure the temporary file is removed, `path` is untouched and IoError
// is thrown.
std::filesystem::path temporary_sibling(const std::filesystem::path& path);
void publish_file_atomic(const std::filesystem::path& temporary, const std::filesystem::path& path);

// The whole content of a file (io::read_regular_file: a regular file of at
// most max_bytes, 1 GiB by default); IoError naming the file otherwise.
std::string read_text_file(const std::filesystem::path& path, std::uintmax_t max_bytes = std::uintmax_t{1} << 30);

// Throws IoError unless `dir` exists (it is created if missing), a file can be
// created in it, and its file system has at least `bytes_needed` bytes free
// (the message then gives both figures).
void ensure_writable_directory(const std::filesystem::path& dir, std::uintmax_t bytes_needed = 0);

// Throws IoError unless write_file_atomic(path, ...) could succeed now: `path`
// is not a directory or other non-regular file, and its directory exists (it
// is not created) and a file can be created in it. Checks an output before the
// work that produces it.
void ensure_writable_file(const std::filesystem::path& path);

}  // namespace swirl::io
