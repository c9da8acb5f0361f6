// `swirl run`: runs a scene (or resumes a run) and prints the closing summary.
//
//   swirl run SCENE [--threads N] [--out DIR] [--steps N | --until T] [--set key=value]... [--summary-json FILE]
//             [--checkpoint-every T] [--checkpoint-every-steps N] [--checkpoint-keep K]
//   swirl run --resume RUN_DIR [--steps N | --until T] [--threads N] [checkpoint options]
//   --render-every K: also draw every K-th frame to OUT/render/ (render_command.cpp, swirl/render)
//
// Under mpirun every rank runs its share (sim/run.hpp, RunOptions::ranks);
// rank 0 prints and writes. Bad input is found alike on every rank and ends
// them all with status 2 (as a scene error: run_cli.cpp prints it once).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <csignal>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli.hpp"
#include "commands.hpp"
#include "flags.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/run_folder.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/run.hpp"
#include "swirl/render/font.hpp"
#include "swirl/render/run_renderer.hpp"

namespace swirl::cli {
namespace {

struct RunArgs {
  std::string scene;
  int threads = 0;
  std::string out;
  std::uint64_t steps = 0;
  double until = 0;
  std::vector<std::string> overrides;
  std::string summary_json;
  std::string on_blowup = "stop";  // "stop" | "warn" (| "off": measurements only, docs/stability.md)
  double checkpoint_every = 0;
  std::uint64_t checkpoint_every_steps = 0;
  std::size_t checkpoint_keep = 2;
  std::string resume;
  bool overwrite = false;
  std::uint64_t render_every = 0;  // draw every K-th frame while running (0: off)
};

// SIGINT/SIGTERM: the first asks the run to stop after the current step (it
// then writes a checkpoint); a second one exits at once. Every file is written
// atomically, so exiting mid-write leaves only a stray temporary file.
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  if (g_stop.exchange(true)) _exit(128 + sig);
  g_signal.store(sig);
}

// Every output path the command was given, checked before the first step
// (not after the run, when a typo would cost the whole run): each can be
// written, none is another's file, none is the scene being read.
void check_outputs(const RunArgs& args, const std::filesystem::path& out_dir) {
  namespace fs = std::filesystem;
  std::vector<io::NamedOutput> outputs{{"--out", out_dir / "scene.toml"}}, inputs;
  if (!args.scene.empty()) inputs.push_back({"scene file", args.scene});
  if (!args.summary_json.empty()) {
    const fs::path json = args.summary_json;
    // The run writes these names in its folder: the summary must not land on one.
    const fs::path rel = fs::absolute(json).lexically_normal().lexically_relative(fs::absolute(out_dir).lexically_normal());
    const std::string name = rel.string();
    if (rel.has_parent_path() ? rel.begin()->string() == "checkpoints" || rel.begin()->string() == "render"
                              : name == "scene.toml" || name == "diagnostics.csv" || name == "probes.csv" ||
                                    name == "manifest.txt" || name.rfind("particles", 0) == 0 ||
                                    name == io::RunFolder::kLockFile)
      throw std::invalid_argument(fmt::format("--summary-json {}: the run writes that file in --out {}; choose another name",
                                              json.string(), out_dir.string()));
    outputs.push_back({"--summary-json", json});
    io::ensure_writable_file(json);
  }
  io::check_distinct_outputs(outputs, inputs);
  if (args.render_every > 0) {
    const fs::path render = out_dir / "render";
    std::error_code ec;
    if (fs::exists(render, ec) && !fs::is_directory(render, ec))
      throw std::invalid_argument(fmt::format("--render-every: {} is not a folder, the pictures cannot go there", render.string()));
  }
}

int run_here(const RunArgs& args) {
  const dist::Communicator& comm = dist::Communicator::world();
  const bool speak = comm.is_root();
  sim::RunOptions options;
  if (comm.distributed()) options.ranks = &comm;
  scene::Scene scene;
  if (!args.resume.empty()) {
    if (!args.scene.empty() || !args.overrides.empty())
      throw std::invalid_argument("--resume continues the scene saved in RUN_DIR; give no SCENE or --set");
    if (args.overwrite) throw std::invalid_argument("--overwrite starts a new run; it cannot go with --resume");
    options.out_dir = args.resume;
    options.resume = true;
    scene = load_scene_file(options.out_dir / "scene.toml");
  } else {
    if (args.scene.empty()) throw std::invalid_argument("give a SCENE file, or --resume RUN_DIR");
    scene = load_scene_file(args.scene, args.overrides);
    options.out_dir = args.out.empty() ? std::filesystem::path("out") / std::filesystem::path(args.scene).stem()
                                       : std::filesystem::path(args.out);
  }
  check_outputs(args, options.out_dir);
  options.threads = args.threads;
  if (args.steps > 0) options.steps = args.steps;
  if (args.until > 0) {
    // The step count the run must reach, ceil(T/dt), has to be one it can count.
    const double steps = std::ceil(args.until / scene.dt);
    if (!std::isfinite(steps) || steps > static_cast<double>(kMaxSteps))
      throw std::invalid_argument(fmt::format(
          "--until {}: that is {:.3g} steps of dt = {}, more than the 2^53 steps a run can count; give a smaller T",
          args.until, args.until / scene.dt, scene.dt));
    options.until = args.until;
  }
  if (args.checkpoint_every > 0) options.checkpoint_every = args.checkpoint_every;
  if (args.checkpoint_every_steps > 0) options.checkpoint_every_steps = args.checkpoint_every_steps;
  options.checkpoint_keep = args.checkpoint_keep;
  options.overwrite = args.overwrite;
  options.on_blow_up = args.on_blowup == "warn" ? OnBlowUp::Warn : args.on_blowup == "off" ? OnBlowUp::Off : OnBlowUp::Stop;
  options.on_warning = [speak](const std::string& w) {
    if (speak) fmt::print(stderr, "{}swirl run: warning: {}\n", ::isatty(STDERR_FILENO) ? "\n" : "", w);
  };
  options.stop = &g_stop;
  if (args.render_every > 0) {
    // Refused up front (status 2) rather than after the first frame: no .vtp
    // frames to draw, or no font. A failure later stops the run (status 1).
    if (std::find(scene.formats.begin(), scene.formats.end(), scene::OutputFormat::Vtp) == scene.formats.end())
      throw std::invalid_argument("--render-every draws .vtp frames: the scene's output.format has no \"vtp\"");
    render::Font{};
    options.on_frame = render::render_every(options.out_dir, args.render_every);
  }
  if (scene.surface != scene::SurfaceFormat::None) {
    // output.surface: the fluid's mesh beside each frame (after any picture of it).
    auto surfaces = render::surface_frames(options.out_dir, render::fluid_surface_of(scene));
    if (options.on_frame)
      options.on_frame = [pictures = std::move(options.on_frame), surfaces = std::move(surfaces)](
                             const std::filesystem::path& frame, double time, const sim::ClaimFile& claim) {
        pictures(frame, time, claim);
        surfaces(frame, time, claim);
      };
    else
      options.on_frame = std::move(surfaces);
  }
  // Cleared first: run_cli() may run many times in one process (the Python module).
  g_stop.store(false);
  g_signal.store(0);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  ProgressDisplay progress(stderr);
  const auto summary = sim::run_scene(scene, options, [&](const auto& p) {
    if (speak) progress.update(p);
  });
  if (!speak) {  // rank 0 reports; the others end with the same status
    if (summary.interrupted) return 128 + g_signal.load();
    return summary.error.empty() && summary.failed_checks.empty() ? 0 : 1;
  }
  progress.finish();
  for (const auto& w : summary.warnings) fmt::print(stderr, "swirl run: warning: {}\n", w);

  const bool failed_checks = !summary.failed_checks.empty();
  fmt::print("{}\n{}",
             summary.interrupted       ? "swirl run: INTERRUPTED"
             : !summary.error.empty()  ? "swirl run: STOPPED"
             : failed_checks           ? "swirl run: FINISHED, BUT CHECKS FAILED"
                                       : "swirl run: done",
             summary_text(summary));
  if (!args.summary_json.empty()) io::write_file_atomic(args.summary_json, summary_json(summary));
  if (summary.interrupted) {
    fmt::print(stderr, "swirl run: interrupted at t = {:.6g} (checkpoint {}); resume with: swirl run --resume {}\n",
               summary.sim_time, summary.last_checkpoint.string(), options.out_dir.string());
    return 128 + g_signal.load();
  }
  if (!summary.error.empty()) {
    fmt::print(stderr, "swirl run: {}\nswirl run: frames written before the failure are intact in {}\n", summary.error,
               options.out_dir.string());
    if (!summary.last_checkpoint.empty())
      fmt::print(stderr, "swirl run: the last checkpoint is {}\n", summary.last_checkpoint.string());
    return 1;
  }
  if (failed_checks) {
    // --on-blowup=warn went on as asked; the results still failed checks, so
    // the status must not say "done" to a script.
    fmt::print(stderr, "swirl run: the run reached its end, but with --on-blowup=warn it went on past failed checks:\n");
    for (const auto& line : summary.failed_checks) fmt::print(stderr, "swirl run:   {}\n", line);
    fmt::print(stderr, "swirl run: the frames in {} show a state the checks rejected; exit status 1\n",
               options.out_dir.string());
    return 1;
  }
  return 0;
}

// On several ranks bad input (std::invalid_argument: a flag, a scene, a
// folder) is found the same way on every rank: a scene error, which every
// rank answers with status 2 and rank 0 prints, instead of one rank's failure.
int run(const RunArgs& args) {
  if (!dist::Communicator::world().distributed()) return run_here(args);
  try {
    return run_here(args);
  } catch (const std::invalid_argument& e) {
    throw scene::SceneError(e.what());
  }
}

}  // namespace

void add_run_command(CLI::App& app, Commands& commands) {
  auto args = std::make_shared<RunArgs>();
  auto* run_cmd = app.add_subcommand("run", "Run a scene file and write its frames");
  run_cmd->add_option("scene", args->scene, "Scene file (TOML)");
  run_cmd->add_option("--threads,-t", args->threads, "Threads (default: all cores, or OMP_NUM_THREADS)")
      ->check(thread_count());
  run_cmd->add_option("--out,-o", args->out, "Output directory (default: out/<scene name>)");
  auto* steps_opt = run_cmd->add_option("--steps", args->steps, "Number of steps to take, replacing the scene's end time")
      ->check(whole_number(1, kMaxSteps));
  run_cmd->add_option("--until", args->until, "Run until this simulated time")->check(positive_finite())->excludes(steps_opt);
  run_cmd->add_option("--checkpoint-every", args->checkpoint_every, "Write a checkpoint every T of simulated time")
      ->check(positive_finite());
  run_cmd->add_option("--checkpoint-every-steps", args->checkpoint_every_steps, "Write a checkpoint every N steps")
      ->check(whole_number(1, kMaxSteps));
  run_cmd->add_option("--checkpoint-keep", args->checkpoint_keep, "Checkpoints to keep (default 2)")
      ->check(whole_number(1, kMaxSteps));
  run_cmd->add_option("--resume", args->resume, "Continue the run in RUN_DIR from its newest valid checkpoint")
      ->type_name("RUN_DIR");
  run_cmd->add_flag("--overwrite", args->overwrite,
                    "Replace the run in --out: delete the files its manifest lists (nothing else) first");
  run_cmd->add_option("--set", args->overrides, "Override a scene key, e.g. --set box.restitution=0.9")
      ->type_name("KEY=VALUE");
  run_cmd->add_option("--summary-json", args->summary_json, "Also write the closing summary as JSON to FILE");
  run_cmd->add_option("--on-blowup", args->on_blowup, "When a blow-up check fails: stop (default) or warn and go on")
      ->check(CLI::IsMember({"stop", "warn", "off"}));
  run_cmd->add_option("--render-every", args->render_every, "Draw every K-th frame as a PNG in OUT/render (see swirl render)")
      ->check(whole_number(1, kMaxSteps));
  commands.push_back({run_cmd, [args] { return run(*args); }, /*distributed=*/true});
}

}  // namespace swirl::cli
