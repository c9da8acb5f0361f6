// An XDMF description (.xdmf) of a run's HDF5 snapshots (io/snapshot.hpp), so
// ParaView (its XDMF reader) opens the series as one time-dependent dataset:
// a temporal collection of one grid per frame, each a polyvertex of the
// frame's particles whose geometry is /PartType<k>/Coordinates and whose
// attributes are the other datasets (scalars, vectors), all read from the
// frame's .h5 file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/io/snapshot.hpp"

namespace swirl::io {

struct XdmfEntry {
  std::string file;  // relative to the .xdmf's directory
  SnapshotLayout layout;
};

// Keeps the frames of one series and rewrites the .xdmf atomically after each
// add(), so the file on disk always lists exactly the frames written so far.
class XdmfSeries {
 public:
  explicit XdmfSeries(std::filesystem::path xdmf_path) : path_(std::move(xdmf_path)) {}

  // Appends a frame and rewrites the .xdmf. Throws IoError on failure.
  void add(const std::string& relative_file, SnapshotLayout layout);
  // Starts from existing entries (a resumed run); does not write.
  void set_entries(std::vector<XdmfEntry> entries) { entries_ = std::move(entries); }

  const std::vector<XdmfEntry>& entries() const { return entries_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::vector<XdmfEntry> entries_;
};

// The XDMF text for these frames (what XdmfSeries writes), the temporal
// collection named `series` (XdmfSeries: the file's stem, "particles" or "boundary").
std::string xdmf_text(const std::vector<XdmfEntry>& entries, std::string_view series = "particles");

}  // namespace swirl::io
