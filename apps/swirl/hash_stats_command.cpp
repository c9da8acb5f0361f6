// `swirl hash-stats`: the thesis's Table 5.2 for a scene, beside the thesis's figures.
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench_seeds.hpp"
#include "cli.hpp"
#include "commands.hpp"
#include "flags.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/hash_stats.hpp"
#include "swirl/sim/run.hpp"

namespace swirl::cli {
namespace {

struct HashStatsArgs {
  std::string scene;
  std::vector<std::string> overrides;
  std::uint64_t steps = 0;
  int threads = 0;
};

// Table 5.2 of the thesis, beside this run's figures.
int hash_stats(const HashStatsArgs& args) {
  const auto scene = load_scene_file(args.scene, args.overrides);
  sim::check_memory(scene);  // before the particles are built, as `swirl run` does
  if (args.threads > 0) parallel::set_thread_count(args.threads);
  const auto s = sim::scene_hash_statistics(scene, args.steps);
  fmt::print("hash-stats: {}: {} particles, h = {} m, {} mean neighbours{}\n", scene.file, s.particles,
             scene.sph->smoothing_length, s.mean_neighbours(),
             args.steps ? fmt::format(", after {} steps", args.steps) : std::string(" (initial positions)"));
  const auto& t = seeds::kThesisTable52;  // typed once, with the other seed figures
  fmt::print("  {:<52} {:>14} {:>30}\n", "", "swirl", fmt::format("thesis, Table 5.2 (N = {})", t.particles));
  fmt::print("  {:<52} {:>14} {:>30}\n", "Hash table size", s.buckets, fmt::format("{} (1.6x particles)", t.buckets));
  fmt::print("  {:<52} {:>13.1f}% {:>29.0f}%\n", "Empty hash buckets (of all buckets)", 100 * s.empty_fraction(),
             100 * t.empty_buckets);
  fmt::print("  {:<52} {:>13.1f}% {:>29.0f}%\n", "Hash buckets with collisions (of non-empty buckets)",
             100 * s.collision_fraction(), 100 * t.colliding_buckets);
  fmt::print("  {:<52} {:>14.2f} {:>30.2f}\n", "Avg. particles in each non-empty bucket", s.particles_per_nonempty_bucket(),
             t.particles_per_bucket);
  fmt::print("  {:<52} {:>13.1f}% {:>29.0f}%\n", "Redundant neighbour tests due to hash collisions",
             100 * s.redundant_test_fraction(), 100 * t.redundant_tests);
  fmt::print("  {:<52} {:>13.2f}% {:>29.1f}%\n", "Duplicate interactions due to hash collisions", 100 * s.duplicate_fraction(),
             100 * t.duplicate_interactions);
  fmt::print("  counts: {} tests, {} redundant, {} interactions, {} duplicates with the check off\n", s.tests,
             s.redundant_tests, s.interactions, s.duplicate_interactions);
  return 0;
}

}  // namespace

void add_hash_stats_command(CLI::App& app, Commands& commands) {
  auto hs = std::make_shared<HashStatsArgs>();
  auto* hash_cmd = app.add_subcommand("hash-stats", "Print the spatial hash statistics of an SPH scene (Table 5.2)");
  hash_cmd->add_option("scene", hs->scene, "Scene file (TOML) with an [sph] section")->required();
  hash_cmd->add_option("--set", hs->overrides, "Override a scene key")->type_name("KEY=VALUE");
  hash_cmd->add_option("--steps", hs->steps, "Run N steps before measuring (default: the initial positions)")
      ->check(whole_number(0, kMaxSteps));
  hash_cmd->add_option("--threads,-t", hs->threads, "Threads")->check(thread_count());
  commands.push_back({hash_cmd, [hs] { return hash_stats(*hs); }});
}

}  // namespace swirl::cli
