// Writing files so that a crash never leaves a half-written one: the bytes go
// to a temporary file in the same directory, which is then renamed over the
// target (rename is atomic within one file system).
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

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

// The whole content of a file; IoError naming the file if it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

// Throws IoError unless `dir` exists (it is created if missing), a file can be
// created in it, and its file system has at least `bytes_needed` bytes free
// (the message then gives both figures).
void ensure_writable_directory(const std::filesystem::path& dir, std::uintmax_t bytes_needed = 0);

}  // namespace swirl::io
