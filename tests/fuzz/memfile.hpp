// The fuzz input as a file the readers can open by path, without touching the
// disk: an in-memory file (memfd), reached as /proc/self/fd/N. Falls back to a
// file in $TMPDIR where memfd_create is unavailable.
#pragma once

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace swirl::fuzz {

class MemFile {
 public:
  MemFile() {
    fd_ = ::memfd_create("swirl-fuzz", MFD_CLOEXEC);
    if (fd_ >= 0) {
      path_ = "/proc/self/fd/" + std::to_string(fd_);
    } else {
      path_ = std::filesystem::temp_directory_path() / ("swirl-fuzz-" + std::to_string(::getpid()));
      fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
      unlink_ = true;
    }
    if (fd_ < 0) {
      std::perror("swirl fuzz: cannot create the input file");
      std::abort();
    }
  }
  ~MemFile() {
    ::close(fd_);
    if (unlink_) ::unlink(path_.c_str());
  }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  // Replaces the file's contents with the input; returns its path.
  const std::filesystem::path& write(const std::uint8_t* data, std::size_t size) {
    if (::ftruncate(fd_, 0) != 0) std::abort();
    std::size_t done = 0;
    while (done < size) {
      const ssize_t n = ::pwrite(fd_, data + done, size - done, static_cast<off_t>(done));
      if (n <= 0) std::abort();
      done += static_cast<std::size_t>(n);
    }
    return path_;
  }

 private:
  int fd_ = -1;
  bool unlink_ = false;
  std::filesystem::path path_;
};

}  // namespace swirl::fuzz
