// The output folder of one run, guarded: what makes a reused or shared folder
// safe (issue 17).
//
// A RunFolder
//  - holds an exclusive lock on the folder for its lifetime (flock on
//    DIR/.swirl.lock, which also records the holder's pid): a second run, or a
//    resume, into the same folder at the same time is refused, naming the pid;
//  - keeps a manifest, DIR/manifest.txt, of every file the run wrote (paths
//    relative to DIR) and the run's identity, rewritten atomically whenever a
//    file is added or removed, so that it always lists at least every file of
//    the run that exists;
//  - never lets the run overwrite a file it did not write: claim() refuses an
//    existing file the manifest does not list (a user's scene.toml, another
//    run's frames);
//  - refuses a folder holding another run's manifest unless asked to overwrite,
//    and then deletes exactly the files that manifest lists, nothing else.
// Invariants: every path in the manifest is relative, inside DIR, without
// "..", and names a regular file; a manifest read from disk that breaks this is
// refused rather than followed (it could point anywhere).
#pragma once

#include <cstdint>
#include <filesystem>
#include <set>
#include <span>
#include <string>

#include "swirl/io/atomic_file.hpp"

namespace swirl::io {

// A folder that cannot be used as asked (locked, another run's, a file that is
// not this run's). The CLI maps it to exit status 2, like any IoError before a run.
class RunFolderError : public IoError {
 public:
  using IoError::IoError;
};

enum class RunFolderMode {
  Fresh,      // a new run: refused if the folder holds another run's manifest
  Overwrite,  // a new run replacing the one in the folder: its listed files are deleted first
  Resume,     // continue the run in the folder: its manifest (and identity) is adopted; refused without one
};

class RunFolder {
 public:
  static constexpr const char* kLockFile = ".swirl.lock";
  static constexpr const char* kManifestFile = "manifest.txt";

  // Creates `dir` if missing, takes its lock, then applies `mode`. `identity`
  // names a new run in the manifest (e.g. the scene file and its hash; a
  // unique id is prepended); on Resume the manifest's identity is kept.
  RunFolder(std::filesystem::path dir, RunFolderMode mode, const std::string& identity);
  ~RunFolder();  // releases the lock
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  const std::filesystem::path& dir() const { return dir_; }
  const std::string& identity() const { return identity_; }

  // Paths below are absolute, dir() / name as the caller built it, or relative
  // to dir().
  // Call before writing `path`: returns its
  // full path, after recording it in the manifest. RunFolderError if it lies
  // outside dir(), or exists and is not this run's. Directories on the way are
  // created. With `sync` the manifest is fsync'ed (claim a checkpoint so: a
  // resume after a power cut then still knows it is this run's).
  std::filesystem::path claim(const std::filesystem::path& path, bool sync = false);
  // Whether the manifest lists `path`.
  bool owns(const std::filesystem::path& path) const;
  // Deletes `path` if it is this run's and drops it from the manifest (e.g. a
  // pruned checkpoint); a path that is not this run's is left alone (false).
  bool remove(const std::filesystem::path& path);
  // This run's files, relative to dir(), sorted.
  const std::set<std::filesystem::path>& files() const { return files_; }

 private:
  std::filesystem::path relative(const std::filesystem::path& path) const;
  void write_manifest(bool sync = false) const;

  std::filesystem::path dir_;
  int lock_fd_ = -1;
  std::string identity_;
  std::set<std::filesystem::path> files_;
};

// One output a command was given: the flag's name (for messages) and its path.
struct NamedOutput {
  std::string flag;
  std::filesystem::path path;
};

// RunFolderError naming both flags if two outputs are the same file (after
// resolving ".", "..", symbolic links and relative paths), or if an output is
// one of the inputs (`inputs`: the files read, e.g. the scene).
void check_distinct_outputs(std::span<const NamedOutput> outputs, std::span<const NamedOutput> inputs = {});

}  // namespace swirl::io
