// Running a scene from start to end: builds the particles and force models the
// scene describes, steps the Simulation, writes frames at output times and
// reports progress. The CLI's `swirl run` is a thin shell around run_scene().
//
// Outputs in RunOptions::out_dir: particles_NNNNNN.vtp (or .csv) per frame and
// particles.pvd listing the .vtp frames with their times; every file is
// written atomically. Frame k is written at the first step whose time is
// ≥ k·output.interval, the initial state is frame 0, and the final state is
// always written. SPH runs also write diagnostics.csv: one row per frame with
// kinetic and potential energy, momentum, density errors and mean neighbours.
//
// Blow-ups (sim/blow_up.hpp, docs/stability.md): a failed check stops the run
// with RunSummary::error naming the step, time, particle, quantity and a fix,
// keeping every frame and checkpoint written before; OnBlowUp::Warn reports it
// through RunOptions::on_warning instead (rate-limited), goes on, and counts it
// in RunSummary::failed_checks. Runs whose forces and walls conserve energy
// also check the relative energy error at each output time against
// simulation.max_energy_error. With
// dt = "adaptive" frames land exactly on the output times, the run ends exactly
// at its end time, and diagnostics.csv gains the step history per frame: steps
// so far, the smallest and largest step since the previous frame, the step the
// controller proposes next and the condition that sets it.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/sim/blow_up.hpp"

namespace swirl {
template <class Real>
class Simulation;
}  // namespace swirl

namespace swirl::sim {

template <class Real>
class Observer;

// What a caller adds to a run (the Python module: forces and callbacks written
// in Python). Called once with the run's simulation, built and not yet started
// or resumed: it may add solvers (they act from the first force evaluation)
// and returns observers. Those act after every step after the frame writer,
// the diagnostics log and the guard, and before the checkpointer and the
// progress report: a checkpoint holds what they changed, so a resumed run goes
// on exactly as the uninterrupted one. Their save_state/load_state go into
// checkpoints like the run's own observers'. They may outlive the run; the
// simulation does not.
template <class Real>
using RunExtension = std::function<std::vector<std::shared_ptr<Observer<Real>>>(Simulation<Real>& sim)>;

// Records a file in the run folder's manifest before it is written and returns
// its full path; throws io::RunFolderError for a file that exists and is not
// this run's (io/run_folder.hpp). Every file a run makes goes through one.
using ClaimFile = std::function<std::filesystem::path(const std::filesystem::path& path)>;
// Called after each frame has been written, with the frame's file, its
// simulated time, and the claim for any file the hook writes itself.
using FrameHook = std::function<void(const std::filesystem::path& frame, double time, const ClaimFile& claim)>;

// The most steps a run counts: time = step·dt stays exact in a double. The
// CLI's flags and a resume's remembered end are held to it.
inline constexpr std::uint64_t kMaxSteps = std::uint64_t{1} << 53;

struct RunOptions {
  std::filesystem::path out_dir = "out";
  int threads = 0;                      // 0: OpenMP's default (OMP_NUM_THREADS or all cores)
  std::optional<std::uint64_t> steps;   // steps to take (from the start, or from the checkpoint on resume)
  std::optional<double> until;          // run until this simulated time instead of the scene's end

  // Checkpoints in out_dir/checkpoints/ (see io/checkpoint.hpp), every
  // `checkpoint_every` of simulated time and/or every `checkpoint_every_steps`
  // steps; the newest `checkpoint_keep` are kept.
  std::optional<double> checkpoint_every;
  std::optional<std::uint64_t> checkpoint_every_steps;
  std::size_t checkpoint_keep = 2;

  // Continue the run in out_dir from its newest valid checkpoint (the scene
  // must be the one saved there, out_dir/scene.toml).
  bool resume = false;
  // A new run into a folder that holds another run: delete that run's files
  // (those its manifest lists, nothing else) first. Without it such a folder
  // is refused (io/run_folder.hpp).
  bool overwrite = false;

  // When set (by a signal handler), the run stops after the current step,
  // writes a checkpoint and returns with RunSummary::interrupted.
  const std::atomic<bool>* stop = nullptr;

  // Called after each frame has been written (e.g. to render it while the run
  // goes on). An exception thrown here stops the run like a write failure.
  FrameHook on_frame;

  // Solvers and observers a caller adds (RunExtension), for float and for
  // double scenes; the one of the scene's precision is called, if set.
  RunExtension<float> extend_float;
  RunExtension<double> extend_double;

  // What a failed blow-up check does (stop, or warn and go on).
  OnBlowUp on_blow_up = OnBlowUp::Stop;
  // Called with each warning of OnBlowUp::Warn, rate-limited: the 1st, 10th,
  // 100th, ... failure of each kind of check.
  std::function<void(const std::string& warning)> on_warning;

  // The ranks to run on (the CLI under mpirun: dist::Communicator::world());
  // null or one rank: this process alone. On several ranks every rank builds
  // the scene (or reads the checkpoint) whole and keeps its share; rank 0
  // alone takes the folder's lock and writes every file, from the whole state
  // gathered to it, so the files are those of a one-rank run byte for byte;
  // the hooks and warnings run on rank 0 only (docs/design/mpi.md).
  const dist::Communicator* ranks = nullptr;
};

// Reported after start() and after every step.
struct RunProgress {
  std::uint64_t step = 0;
  std::uint64_t first_step = 0;   // where this invocation started (the checkpoint's step on resume)
  std::uint64_t total_steps = 0;  // the step the run ends at, ≥ step; adaptive steps: an estimate from the current step size
  double sim_time = 0;       // in time_unit
  double wall_seconds = 0;   // since the run started stepping
  std::string_view time_unit = "s";  // "s" (simulation.units = "si"), "" in N-body units
};

struct RunSummary {
  std::string scene_file;
  std::string precision;                // "float" | "double"
  std::filesystem::path out_dir;
  int threads = 1;
  std::size_t particles = 0;            // at the start (of this run, or of the resumed state)
  std::size_t particles_end = 0;        // at the end: differs with inlets and outlets
  std::uint64_t steps = 0;              // steps actually taken
  double sim_time = 0;                  // reached, in time_unit
  std::string time_unit = "s";          // "s" (simulation.units = "si"), "" in N-body units
  double wall_seconds = 0;              // stepping and output, without set-up
  double steps_per_second = 0;
  std::vector<std::pair<std::string, double>> phases;  // seconds per phase
  std::size_t bytes_per_particle = 0;   // particle storage (all fields and ids) and SPH search scratch / particles
  std::size_t frames = 0;               // frames written
  // Solver figures, e.g. {"mean_neighbours", 24.9} for SPH runs (mean over steps).
  std::vector<std::pair<std::string, double>> metrics;
  std::string error;                    // empty when the run completed
  std::string blow_up;                  // the blow-up's cause (to_string(BlowUpCause)) when it stopped the run
  bool interrupted = false;             // stopped by RunOptions::stop (a checkpoint was written)
  std::uint64_t first_step = 0;         // 0, or the checkpoint's step when resumed
  std::filesystem::path last_checkpoint;  // the newest checkpoint written or resumed from
  std::vector<std::string> warnings;    // e.g. a corrupt checkpoint skipped on resume
  // OnBlowUp::Warn: one line per kind of check that failed and went on,
  // e.g. "20 steps failed the 'time-step condition' check". A run with any
  // did not do what was asked, though it reached its end (the CLI exits 1).
  std::vector<std::string> failed_checks;
};

// What of a scene does not run on several ranks yet ("self-gravity
// ([nbody])", ...); empty when all of it does.
std::string distributed_support(const scene::Scene& scene);

// Refuses, before anything is allocated, a scene whose particles would not fit
// in the free memory (std::invalid_argument with the estimate and the limit;
// sim/footprint.hpp). On several ranks (`ranks` distributed; collective) each
// rank's share is counted against the memory of the host it runs on.
void check_memory(const scene::Scene& scene, const dist::Communicator* ranks = nullptr);

// Runs the scene. Before running anything it calls check_memory(), builds the
// particles, and throws io::IoError if out_dir cannot be written, has no room
// for the first outputs, or (on resume) holds no valid checkpoint of this scene. A blow-up
// or a write failure during the run stops it, keeps every frame and checkpoint
// already written, and is reported in RunSummary::error. The effective scene is
// saved as out_dir/scene.toml.
RunSummary run_scene(const scene::Scene& scene, const RunOptions& options,
                     const std::function<void(const RunProgress&)>& on_progress = {});

}  // namespace swirl::sim
