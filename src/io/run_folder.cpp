#include "swirl/io/run_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <chrono>
#include <sstream>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "swirl/io/read_file.hpp"

namespace swirl::io {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int err) { return std::generic_category().message(err); }

// A manifest path is followed (deleted on overwrite) only if it stays inside
// the folder: relative, no "..", no "." tricks, no empty name.
bool is_safe_relative(const fs::path& p) {
  if (p.empty() || p.is_absolute() || p.has_root_name()) return false;
  for (const auto& part : p)
    if (part == ".." || part == "." || part.empty()) return false;
  const std::string s = p.string();
  return s.find('\n') == std::string::npos && s.find('\r') == std::string::npos;
}

struct Manifest {
  std::string identity;
  std::set<fs::path> files;
};

// Reads DIR/manifest.txt; RunFolderError if it is malformed or lists a path
// outside the folder (it is then not followed at all).
Manifest read_manifest(const fs::path& file) {
  const std::string text = read_regular_file(file, kMaxSeriesBytes);
  Manifest m;
  std::istringstream in(text);
  std::string line;
  bool seen_run = false;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    if (line.rfind("run ", 0) == 0 && !seen_run) {
      m.identity = line.substr(4);
      seen_run = true;
    } else if (line.rfind("file ", 0) == 0) {
      const fs::path p = line.substr(5);
      if (!is_safe_relative(p))
        throw RunFolderError(fmt::format("{}:{}: '{}' is not a path inside the run folder; the manifest is not used",
                                         file.string(), number, p.string()));
      m.files.insert(p.lexically_normal());
    } else {
      throw RunFolderError(fmt::format("{}:{}: not a swirl manifest line", file.string(), number));
    }
  }
  if (!seen_run) throw RunFolderError(fmt::format("{}: not a swirl manifest (no 'run' line)", file.string()));
  return m;
}

std::string new_identity(const std::string& what) {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  std::string id = fmt::format("{}@{}:{}", ::getpid(), host, ns);
  if (!what.empty()) id += " " + what;
  for (char& c : id)
    if (c == '\n' || c == '\r') c = ' ';
  return id;
}

// Deletes a file listed in another run's manifest: only a regular file or a
// symbolic link (never what it points to), never a directory.
void remove_listed(const fs::path& dir, const fs::path& rel) {
  const fs::path p = dir / rel;
  std::error_code ec;
  const auto st = fs::symlink_status(p, ec);
  if (ec || !(fs::is_regular_file(st) || fs::is_symlink(st))) return;
  if (!fs::remove(p, ec) && ec)
    throw RunFolderError(fmt::format("{}: cannot delete the earlier run's file: {}", p.string(), ec.message()));
  // Its folders (checkpoints/, render/) go too once empty; remove() of a
  // non-empty folder fails harmlessly.
  for (fs::path parent = rel.parent_path(); !parent.empty(); parent = parent.parent_path())
    if (!fs::remove(dir / parent, ec)) break;
}

}  // namespace

RunFolder::RunFolder(fs::path dir, RunFolderMode mode, const std::string& identity) : dir_(std::move(dir)) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create directory: {}", dir_.string(), ec.message()));

  const fs::path lock = dir_ / kLockFile;
  // O_NOFOLLOW: a symbolic link planted as the lock file is refused, not followed.
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  if (lock_fd_ < 0) throw IoError(fmt::format("{}: cannot open the lock file: {}", lock.string(), errno_text(errno)));
  struct stat st {};
  if (::fstat(lock_fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(lock_fd_);
    throw RunFolderError(fmt::format("{}: the lock file is not a regular file", lock.string()));
  }
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char pid[32] = {};
    const ssize_t n = ::pread(lock_fd_, pid, sizeof pid - 1, 0);
    ::close(lock_fd_);
    lock_fd_ = -1;
    std::string holder = "another swirl run";
    const std::string text = n > 0 ? std::string(pid, static_cast<std::size_t>(n)) : std::string();
    const std::string digits = text.substr(0, text.find('\n'));
    if (!digits.empty() && digits.find_first_not_of("0123456789") == std::string::npos)
      holder += fmt::format(" (pid {})", digits);
    if (err == EWOULDBLOCK)
      throw RunFolderError(fmt::format("{}: {} is using this folder; wait for it to end, or choose another folder",
                                       dir_.string(), holder));
    throw IoError(fmt::format("{}: cannot lock: {}", lock.string(), errno_text(err)));
  }
  // The holder's pid, for the message a second run prints. The lock itself is
  // the flock, which the kernel drops when this process ends (no stale locks).
  const std::string me = fmt::format("{}\n", ::getpid());
  // Best effort: if it fails, the lock holds and the message lacks the pid.
  if (::ftruncate(lock_fd_, 0) == 0) (void)!::pwrite(lock_fd_, me.data(), me.size(), 0);

  try {
    const fs::path manifest = dir_ / kManifestFile;
    const bool has_manifest = fs::exists(fs::symlink_status(manifest, ec));
    switch (mode) {
      case RunFolderMode::Resume: {
        if (!has_manifest)
          throw RunFolderError(fmt::format("{}: no {} (not a swirl run folder, or written by a swirl without manifests)",
                                           dir_.string(), kManifestFile));
        Manifest m = read_manifest(manifest);
        identity_ = std::move(m.identity);
        files_ = std::move(m.files);
        break;
      }
      case RunFolderMode::Fresh:
        if (has_manifest) {
          const Manifest m = read_manifest(manifest);
          throw RunFolderError(fmt::format(
              "{}: holds another run ({}, {} files); give --overwrite to replace its files, --resume to continue it, "
              "or choose another folder",
              dir_.string(), m.identity, m.files.size()));
        }
        identity_ = new_identity(identity);
        break;
      case RunFolderMode::Overwrite:
        if (has_manifest) {
          // Read in full (and checked) before anything is deleted.
          const Manifest m = read_manifest(manifest);
          for (const auto& rel : m.files) remove_listed(dir_, rel);
        }
        identity_ = new_identity(identity);
        break;
    }
    write_manifest();
  } catch (...) {
    ::close(lock_fd_);
    throw;
  }
}

RunFolder::~RunFolder() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // closing the descriptor releases the flock
}

fs::path RunFolder::relative(const fs::path& path) const {
  fs::path rel;
  if (path.is_absolute()) {
    std::error_code ec;
    rel = fs::weakly_canonical(path, ec).lexically_relative(fs::weakly_canonical(fs::absolute(dir_), ec));
  } else if (std::mismatch(dir_.begin(), dir_.end(), path.begin(), path.end()).first == dir_.end()) {
    rel = path.lexically_relative(dir_);  // dir() / name, as the caller built it
  } else {
    rel = path.lexically_normal();
  }
  if (!is_safe_relative(rel) || rel == kLockFile || rel == kManifestFile)
    throw RunFolderError(fmt::format("{}: not a file a run may write in {}", path.string(), dir_.string()));
  return rel;
}

fs::path RunFolder::claim(const fs::path& path, bool sync) {
  const fs::path rel = relative(path);
  const fs::path full = dir_ / rel;
  if (files_.count(rel)) return full;
  std::error_code ec;
  if (fs::exists(fs::symlink_status(full, ec)))
    throw RunFolderError(fmt::format("{}: exists and was not written by this run; swirl does not overwrite it "
                                     "(move it away, or choose another folder)",
                                     full.string()));
  if (!rel.parent_path().empty()) {
    fs::create_directories(full.parent_path(), ec);
    if (ec) throw IoError(fmt::format("{}: cannot create directory: {}", full.parent_path().string(), ec.message()));
  }
  files_.insert(rel);
  try {
    write_manifest(sync);  // listed before it is written: the manifest never misses a file of this run
  } catch (...) {
    files_.erase(rel);
    throw;
  }
  return full;
}

bool RunFolder::owns(const fs::path& path) const {
  try {
    return files_.count(relative(path)) > 0;
  } catch (const RunFolderError&) {
    return false;
  }
}

bool RunFolder::remove(const fs::path& path) {
  if (!owns(path)) return false;
  const fs::path rel = relative(path);
  std::error_code ec;
  fs::remove(dir_ / rel, ec);
  if (ec) throw IoError(fmt::format("{}: cannot delete: {}", (dir_ / rel).string(), ec.message()));
  files_.erase(rel);
  write_manifest();
  return true;
}

void RunFolder::write_manifest(bool sync) const {
  std::string text = "# swirl run manifest: the files this run wrote, relative to this folder\n";
  text += fmt::format("run {}\n", identity_);
  for (const auto& f : files_) text += fmt::format("file {}\n", f.string());
  write_file_atomic(dir_ / kManifestFile, text, sync);
}

void check_distinct_outputs(std::span<const NamedOutput> outputs, std::span<const NamedOutput> inputs) {
  const auto key = [](const fs::path& p) {
    std::error_code ec;
    const fs::path k = fs::weakly_canonical(fs::absolute(p), ec);
    return ec ? fs::absolute(p).lexically_normal() : k;
  };
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const fs::path a = key(outputs[i].path);
    for (std::size_t j = i + 1; j < outputs.size(); ++j)
      if (a == key(outputs[j].path))
        throw RunFolderError(fmt::format("{} and {} name the same file, {}: one would overwrite the other",
                                         outputs[i].flag, outputs[j].flag, outputs[i].path.string()));
    for (const auto& in : inputs)
      if (a == key(in.path))
        throw RunFolderError(fmt::format("{} {} is the {} swirl reads: writing it would destroy it", outputs[i].flag,
                                         outputs[i].path.string(), in.flag));
  }
}

}  // namespace swirl::io
