#include "swirl/io/read_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"

namespace swirl::io {
namespace {

std::string errno_text(int err) { return std::generic_category().message(err); }

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Closes the descriptor on every exit, including a throw.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::uintmax_t max_particle_file_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  // Unknown: no bound but the address space.
  if (pages <= 0 || page <= 0) return UINTMAX_MAX;
  return static_cast<std::uintmax_t>(pages) * static_cast<std::uintmax_t>(page);
}

std::string read_regular_file(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer,
  // before fstat could tell what it is. O_NOCTTY: a terminal never becomes ours.
  const Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)};
  if (f.fd < 0) throw IoError(fmt::format("{}: cannot open: {}", path.string(), errno_text(errno)));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw IoError(fmt::format("{}: cannot stat: {}", path.string(), errno_text(errno)));
  if (!S_ISREG(st.st_mode))
    throw IoError(fmt::format("{}: is {}; swirl reads only regular files", path.string(), kind_of(st.st_mode)));
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes)
    throw IoError(fmt::format("{}: {} bytes, more than a valid file of this kind can hold ({} bytes)", path.string(),
                              size, max_bytes));

  std::string data;
  data.reserve(static_cast<std::size_t>(size));
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(fmt::format("{}: read failed: {}", path.string(), errno_text(errno)));
    }
    if (data.size() + static_cast<std::size_t>(n) > max_bytes)
      throw IoError(fmt::format("{}: grew past {} bytes while being read, more than a valid file of this kind can hold",
                                path.string(), max_bytes));
    data.append(buf, static_cast<std::size_t>(n));
  }
  return data;
}

}  // namespace swirl::io
