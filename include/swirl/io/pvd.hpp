// A ParaView data collection (.pvd): the list of a run's frames with their
// times, so ParaView opens the whole series as one time-dependent dataset.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace swirl::io {

struct PvdEntry {
  double time = 0;
  std::string file;  // relative to the .pvd's directory
};

// Keeps the entries of one series and rewrites the .pvd atomically after each
// add(), so the file on disk always lists exactly the frames written so far.
class PvdSeries {
 public:
  explicit PvdSeries(std::filesystem::path pvd_path);

  // Appends a frame and rewrites the .pvd. Throws IoError on failure.
  void add(double time, const std::string& relative_file);

  // Starts from existing entries (a resumed run); does not write.
  void set_entries(std::vector<PvdEntry> entries) { entries_ = std::move(entries); }

  const std::vector<PvdEntry>& entries() const { return entries_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::vector<PvdEntry> entries_;
};

// Reads the entries of a .pvd written by PvdSeries. Throws IoError.
std::vector<PvdEntry> read_pvd(const std::filesystem::path& path);

}  // namespace swirl::io
