// swirl: the command-line tool. The only place that knows about files and flags.
//
//   swirl run SCENE [--threads N] [--out DIR] [--steps N | --until T] [--set key=value]... [--summary-json FILE]
//             [--checkpoint-every T] [--checkpoint-every-steps N] [--checkpoint-keep K]
//   swirl run --resume RUN_DIR [--steps N | --until T] [--threads N] [checkpoint options]
//   swirl hash-stats SCENE [--set key=value]... [--steps N] [--threads N]
//   swirl bench sph|gravity [options]
//   swirl info
//
// Exit status: 0 done, 1 the run failed (blow-up, write error), 2 bad input,
// 130 / 143 stopped by SIGINT / SIGTERM after writing a checkpoint.
#include <omp.h>
#include <unistd.h>

#include <atomic>
#include <csignal>

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "bench.hpp"
#include "cli.hpp"
#include "swirl/config.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/hash_stats.hpp"
#include "swirl/sim/run.hpp"

namespace {

// Widest SIMD registers the compiler was allowed to use for this binary.
int vector_width_bits() {
#if defined(__AVX512F__)
  return 512;
#elif defined(__AVX__)
  return 256;
#elif defined(__SSE2__) || defined(__ARM_NEON)
  return 128;
#else
  return 0;
#endif
}

int print_info() {
  fmt::print("swirl {}\n", SWIRL_VERSION);
  fmt::print("  git revision     {}\n", SWIRL_GIT_REVISION);
  fmt::print("  build type       {}\n", SWIRL_BUILD_TYPE);
  fmt::print("  compiler         {}\n", SWIRL_COMPILER);
  fmt::print("  OpenMP           {} (threads {}, processors {})\n", _OPENMP, omp_get_max_threads(), omp_get_num_procs());
  fmt::print("  vector width     {} bits ({} floats, {} doubles)\n", vector_width_bits(), vector_width_bits() / 32,
             vector_width_bits() / 64);
  return 0;
}

struct RunArgs {
  std::string scene;
  int threads = 0;
  std::string out;
  std::uint64_t steps = 0;
  double until = 0;
  std::vector<std::string> overrides;
  std::string summary_json;
  double checkpoint_every = 0;
  std::uint64_t checkpoint_every_steps = 0;
  std::size_t checkpoint_keep = 2;
  std::string resume;
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

int run(const RunArgs& args) {
  swirl::sim::RunOptions options;
  swirl::scene::Scene scene;
  if (!args.resume.empty()) {
    if (!args.scene.empty() || !args.overrides.empty())
      throw std::invalid_argument("--resume continues the scene saved in RUN_DIR; give no SCENE or --set");
    options.out_dir = args.resume;
    options.resume = true;
    scene = swirl::scene::load_scene(options.out_dir / "scene.toml");
  } else {
    if (args.scene.empty()) throw std::invalid_argument("give a SCENE file, or --resume RUN_DIR");
    scene = swirl::scene::load_scene(args.scene, args.overrides);
    options.out_dir = args.out.empty() ? std::filesystem::path("out") / std::filesystem::path(args.scene).stem()
                                       : std::filesystem::path(args.out);
  }
  options.threads = args.threads;
  if (args.steps > 0) options.steps = args.steps;
  if (args.until > 0) options.until = args.until;
  if (args.checkpoint_every > 0) options.checkpoint_every = args.checkpoint_every;
  if (args.checkpoint_every_steps > 0) options.checkpoint_every_steps = args.checkpoint_every_steps;
  options.checkpoint_keep = args.checkpoint_keep;
  options.stop = &g_stop;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  swirl::cli::ProgressDisplay progress(stderr);
  const auto summary = swirl::sim::run_scene(scene, options, [&](const auto& p) { progress.update(p); });
  progress.finish();
  for (const auto& w : summary.warnings) fmt::print(stderr, "swirl run: warning: {}\n", w);

  fmt::print("{}\n{}",
             summary.interrupted ? "swirl run: INTERRUPTED" : (summary.error.empty() ? "swirl run: done" : "swirl run: STOPPED"),
             swirl::cli::summary_text(summary));
  if (!args.summary_json.empty()) swirl::io::write_file_atomic(args.summary_json, swirl::cli::summary_json(summary));
  if (summary.interrupted) {
    fmt::print(stderr, "swirl run: interrupted at t = {:.6g} (checkpoint {}); resume with: swirl run --resume {}\n",
               summary.sim_time, summary.last_checkpoint.string(), options.out_dir.string());
    return 128 + g_signal.load();
  }
  if (!summary.error.empty()) {
    fmt::print(stderr, "swirl run: {}\nswirl run: frames written before the failure are intact in {}\n", summary.error,
               options.out_dir.string());
    return 1;
  }
  return 0;
}

struct HashStatsArgs {
  std::string scene;
  std::vector<std::string> overrides;
  std::uint64_t steps = 0;
  int threads = 0;
};

// Table 5.2 of the thesis, beside this run's figures.
int hash_stats(const HashStatsArgs& args) {
  const auto scene = swirl::scene::load_scene(args.scene, args.overrides);
  swirl::sim::check_memory(scene);  // before the particles are built, as `swirl run` does
  if (args.threads > 0) swirl::parallel::set_thread_count(args.threads);
  const auto s = swirl::sim::scene_hash_statistics(scene, args.steps);
  fmt::print("hash-stats: {}: {} particles, h = {} m, {} mean neighbours{}\n", scene.file, s.particles,
             scene.sph->smoothing_length, s.mean_neighbors(),
             args.steps ? fmt::format(", after {} steps", args.steps) : std::string(" (initial positions)"));
  fmt::print("  {:<52} {:>14} {:>30}\n", "", "swirl", "thesis, Table 5.2 (N = 15000)");
  fmt::print("  {:<52} {:>14} {:>30}\n", "Hash table size", s.buckets, "24001 (1.6x particles)");
  fmt::print("  {:<52} {:>13.1f}% {:>30}\n", "Empty hash buckets (of all buckets)", 100 * s.empty_fraction(), "89%");
  fmt::print("  {:<52} {:>13.1f}% {:>30}\n", "Hash buckets with collisions (of non-empty buckets)",
             100 * s.collision_fraction(), "5%");
  fmt::print("  {:<52} {:>14.2f} {:>30}\n", "Avg. particles in each non-empty bucket", s.particles_per_nonempty_bucket(),
             "5.94");
  fmt::print("  {:<52} {:>13.1f}% {:>30}\n", "Redundant neighbour tests due to hash collisions",
             100 * s.redundant_test_fraction(), "13%");
  fmt::print("  {:<52} {:>13.2f}% {:>30}\n", "Duplicate interactions due to hash collisions", 100 * s.duplicate_fraction(),
             "0.2%");
  fmt::print("  counts: {} tests, {} redundant, {} interactions, {} duplicates with the check off\n", s.tests,
             s.redundant_tests, s.interactions, s.duplicate_interactions);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // A file-size limit must make writes fail (and the run stop cleanly), not kill us.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"swirl: particle simulation (SPH fluids, Barnes-Hut gravity)", "swirl"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("swirl ") + SWIRL_VERSION + " (" + SWIRL_GIT_REVISION + ")");

  RunArgs args;
  auto* run_cmd = app.add_subcommand("run", "Run a scene file and write its frames");
  run_cmd->add_option("scene", args.scene, "Scene file (TOML)");
  run_cmd->add_option("--threads,-t", args.threads, "Threads (default: all cores, or OMP_NUM_THREADS)")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--out,-o", args.out, "Output directory (default: out/<scene name>)");
  auto* steps_opt = run_cmd->add_option("--steps", args.steps, "Number of steps to take, replacing the scene's end time")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--until", args.until, "Run until this simulated time")->check(CLI::PositiveNumber)->excludes(steps_opt);
  run_cmd->add_option("--checkpoint-every", args.checkpoint_every, "Write a checkpoint every T of simulated time")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--checkpoint-every-steps", args.checkpoint_every_steps, "Write a checkpoint every N steps")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--checkpoint-keep", args.checkpoint_keep, "Checkpoints to keep (default 2)")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--resume", args.resume, "Continue the run in RUN_DIR from its newest valid checkpoint")
      ->type_name("RUN_DIR");
  run_cmd->add_option("--set", args.overrides, "Override a scene key, e.g. --set box.restitution=0.9")
      ->type_name("KEY=VALUE");
  run_cmd->add_option("--summary-json", args.summary_json, "Also write the closing summary as JSON to FILE");

  HashStatsArgs hs;
  auto* hash_cmd = app.add_subcommand("hash-stats", "Print the spatial hash statistics of an SPH scene (Table 5.2)");
  hash_cmd->add_option("scene", hs.scene, "Scene file (TOML) with an [sph] section")->required();
  hash_cmd->add_option("--set", hs.overrides, "Override a scene key")->type_name("KEY=VALUE");
  hash_cmd->add_option("--steps", hs.steps, "Run N steps before measuring (default: the initial positions)");
  hash_cmd->add_option("--threads,-t", hs.threads, "Threads")->check(CLI::PositiveNumber);

  swirl::cli::BenchArgs bench;
  auto* bench_cmd = app.add_subcommand("bench", "Measure the seeds' performance tables on this machine");
  bench_cmd->require_subcommand(1);
  auto* bench_sph = bench_cmd->add_subcommand("sph", "Steps per second of the thesis's random box (Tables 5.1, 5.3)");
  bench_sph->add_option("--particles", bench.particles, "Particle counts")->delimiter(',');
  bench_sph->add_option("--neighbours", bench.neighbours, "Target neighbour counts")->delimiter(',');
  bench_sph->add_option("--threads", bench.threads, "Thread counts")->delimiter(',');
  bench_sph->add_option("--steps", bench.steps, "Timed steps")->check(CLI::PositiveNumber);
  bench_sph->add_option("--warmup", bench.warmup, "Steps before timing")->check(CLI::NonNegativeNumber);
  auto* bench_grav = bench_cmd->add_subcommand("gravity", "Seconds for Barnes-Hut iterations (the paper's Table 2)");
  bench_grav->add_option("--particles", bench.gravity_particles, "Particle counts")->delimiter(',');
  bench_grav->add_option("--threads", bench.threads, "Thread counts")->delimiter(',');
  bench_grav->add_option("--schemes", bench.schemes, "subdomain,subtree,global")->delimiter(',');
  bench_grav->add_option("--iterations", bench.iterations, "Iterations")->check(CLI::PositiveNumber);
  bench_grav->add_option("--opening", bench.opening, "Opening criterion lambda")->check(CLI::Range(0.0, 1.0));

  app.add_subcommand("info", "Print version, build and machine facts");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (app.got_subcommand("info")) return print_info();
    if (app.got_subcommand("hash-stats")) return hash_stats(hs);
    if (bench_sph->parsed()) return swirl::cli::bench_sph(bench);
    if (bench_grav->parsed()) return swirl::cli::bench_gravity(bench);
    return run(args);
  } catch (const swirl::scene::SceneError& e) {
    fmt::print(stderr, "swirl: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "swirl: error: {}\n", e.what());
    return 2;
  }
}
