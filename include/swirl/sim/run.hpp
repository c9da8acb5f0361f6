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
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "swirl/scene/scene.hpp"

namespace swirl::sim {

struct RunOptions {
  std::filesystem::path out_dir = "out";
  int threads = 0;                      // 0: OpenMP's default (OMP_NUM_THREADS or all cores)
  std::optional<std::uint64_t> steps;   // replaces the scene's step count
};

// Reported after start() and after every step.
struct RunProgress {
  std::uint64_t step = 0;
  std::uint64_t total_steps = 0;
  double sim_time = 0;       // s
  double wall_seconds = 0;   // since the run started stepping
};

struct RunSummary {
  std::string scene_file;
  std::string precision;                // "float" | "double"
  std::filesystem::path out_dir;
  int threads = 1;
  std::size_t particles = 0;
  std::uint64_t steps = 0;              // steps actually taken
  double sim_time = 0;                  // s reached
  double wall_seconds = 0;              // stepping and output, without set-up
  double steps_per_second = 0;
  std::vector<std::pair<std::string, double>> phases;  // seconds per phase
  std::size_t bytes_per_particle = 0;   // particle storage (all fields and ids) / particles
  std::size_t frames = 0;               // frames written
  // Solver figures, e.g. {"mean_neighbours", 24.9} for SPH runs (mean over steps).
  std::vector<std::pair<std::string, double>> metrics;
  std::string error;                    // empty when the run completed
};

// Runs the scene. Throws io::IoError before doing any work if out_dir cannot be
// written. A blow-up during the run stops it, keeps every frame already
// written, and is reported in RunSummary::error.
RunSummary run_scene(const scene::Scene& scene, const RunOptions& options,
                     const std::function<void(const RunProgress&)>& on_progress = {});

}  // namespace swirl::sim
