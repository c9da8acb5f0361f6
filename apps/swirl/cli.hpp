// Pieces of the swirl command-line tool shared between its source files.
#pragma once

#include <cstdio>
#include <filesystem>
#include <span>
#include <string>

#include "swirl/scene/scene.hpp"
#include "swirl/sim/run.hpp"

namespace swirl::cli {

// Shows run progress on stderr: a redrawn bar with steps/s and ETA on a
// terminal, a plain line every ~5 s (and at the end) otherwise.
class ProgressDisplay {
 public:
  explicit ProgressDisplay(std::FILE* out);
  void update(const sim::RunProgress& p);
  // Ends the bar's line (call once after the run).
  void finish();

 private:
  std::FILE* out_;
  bool terminal_;
  double last_shown_ = -1e300;
  bool drawn_ = false;
};

// A scene file read by io::read_regular_file (a FIFO or device is refused, not
// waited on; at most io::kMaxSceneBytes) and parsed with the overrides.
scene::Scene load_scene_file(const std::filesystem::path& file, std::span<const std::string> overrides = {});

// The closing summary as aligned text lines.
std::string summary_text(const sim::RunSummary& s);
// The closing summary as a JSON object (for scripts).
std::string summary_json(const sim::RunSummary& s);

}  // namespace swirl::cli
