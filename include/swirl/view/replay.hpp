// replay_run(): a finished run served to the browser (`swirl view RUN_DIR`),
// the page of a live run with a time slider over the run's frames.
//
// A run folder is what `swirl run` writes: particles.pvd and its .vtp frames,
// and/or particles_NNNNNN.h5 snapshots (with particles.xdmf), and scene.toml
// (the effective scene: the box the positions are quantised in, whether it is
// a fluid or a gravity run). open_run() lists the frames, from particles.pvd
// (VTK, the default when present) or from the particles_*.h5 files in name
// order, their times from their headers (no values read). It reads the folder
// without taking its lock (io/run_folder.hpp), so a run still writing it may
// be watched: the frames listed are those present when the session began.
//
// Frames are read lazily, one when it is to be shown, with swirl's own
// readers (io::read_vtp, io::read_snapshot), and kept until another is shown:
// the colour can change without reading again. What can colour the particles
// is found in the first frame: "speed" (|velocity|), every scalar point array
// (density, pressure, mass, potential, integer fields such as time_bin) and
// the magnitude of every other vector ("|acceleration|"); snapshots' Gadget
// names are given swirl's (Velocities: velocity, Density: density, ...).
//
// The session's thread (the caller's) reads, encodes (view/wire.hpp; a
// frame's step field holds its index in the series) and publishes frames; the
// server's thread only queues the page's controls. Controls: play (resume;
// from the first frame when at the last), pause, step (the next frame), reset
// (the first frame), speed (frames per second of playback, 0: as fast as
// frames are read, at most --fps), colour, and seek (a frame by its index).
// A burst of seeks (a dragged slider) shows only the last; a seek is always
// answered by a frame, also one to the frame shown. The push and the
// live parameters are refused (logged, counted, told to the page). The
// surface (a fluid's run whose frames have masses: the scene's ρ0, else each
// particle's density, gives the volumes) is made by a Mesher
// (view/mesher.hpp) from each frame shown while some viewer has it on; a run
// without one refuses the control (and --surface, at once). A frame
// that cannot be read pauses the replay on the frame before, with an error
// naming the file on the page and in the log.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "swirl/scene/scene.hpp"
#include "swirl/view/live_run.hpp"

namespace swirl::view {

enum class ReplayFormat { Auto, Vtp, Hdf5 };  // Auto: particles.pvd's .vtp frames when present, else .h5

struct ReplayEntry {
  double time = 0;
  std::filesystem::path file;  // absolute, or relative to the working directory
};

struct RunFrames {
  std::filesystem::path dir;
  std::vector<ReplayEntry> frames;
  std::optional<scene::Scene> scene;  // scene.toml, when the folder has one that reads
  std::string scene_note;             // why not, when it has one that does not
};

// Lists the frames of a run folder. Throws io::IoError naming the folder when
// it is not one (no particles.pvd and no particles_*.h5, or none of the
// format asked for), or naming the file that cannot be read (the .pvd, a
// snapshot's header).
RunFrames open_run(const std::filesystem::path& dir, ReplayFormat format = ReplayFormat::Auto);

// One frame as the view needs it.
struct ReplayFrame {
  double time = 0;
  std::vector<float> x, y, z;
  std::vector<std::pair<std::string, std::vector<float>>> fields;  // what can colour it, in the order above
};

// Reads a .vtp or .h5 frame (by its extension); a run's particle frame comes
// with the boundary frame in force at it, its particles appended
// (io::boundary_frame_for). Throws io::IoError naming the file when it cannot
// be read, or its arrays disagree in length.
ReplayFrame read_replay_frame(const std::filesystem::path& file);

// Serves `run` until *options.stop (options.threads and start_paused: paused
// on the first frame, else playing). Throws io::IoError when the first frame
// cannot be read, std::runtime_error when the server cannot listen.
ViewResult replay_run(const RunFrames& run, const ViewOptions& options);

}  // namespace swirl::view
