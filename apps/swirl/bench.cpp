// `swirl bench SUITE`: the seeds' experiments, reproducible (bench.hpp).
//
//   swirl bench sph-table  [--sizes ...] [--neighbours 15,25] [--strategy hash,grid] [--settle 3000] [--steps N]
//   swirl bench hash-stats [--particles 15000] [--neighbours 25] [--buckets 24001] [--settle 500] [--steps N]
//   swirl bench bh-table   [--sizes 1024,...,32768] [--schemes ...] [--iterations 50] [--opening 0.5]
//   swirl bench bh-lambda  [--sizes 4096,32768] [--lambdas 0.3,0.5,0.7,0.9] [--schemes ...] [--iterations 20]
//   swirl bench bh-phases  [--sizes ...] [--schemes subtree,subtree+paper] [--iterations 50] [--opening 0.5]
//   swirl bench bh-opt     [--sizes 1024,...,32768] [--schemes subtree] [--iterations N] [--rounds 3]
//                          [--opening 0.5] [--bin-dir DIR]
// and on every suite: --out DIR (default bench/results/<suite>), --threads 1,2 (default 1 .. all), --quick.
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "bench.hpp"
#include "commands.hpp"
#include "flags.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::cli {
namespace {

// The command line as typed (for the records), from /proc/self/cmdline.
std::string command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string out;
  for (std::size_t i = 0; i < raw.size();) {
    const std::size_t end = raw.find('\0', i);
    std::string arg = raw.substr(i, end == std::string::npos ? std::string::npos : end - i);
    if (i == 0) arg = "swirl";  // not the build directory's path
    if (!out.empty()) out += ' ';
    out += arg.find_first_of(" \"'") == std::string::npos ? arg : fmt::format("'{}'", arg);
    if (end == std::string::npos) break;
    i = end + 1;
  }
  return out.empty() ? "swirl bench" : out;
}

CLI::App* add_suite(CLI::App* bench, Commands& commands, const std::string& name, const std::string& help,
                    const std::shared_ptr<bench::CommonArgs>& common, std::function<int()> action) {
  auto* cmd = bench->add_subcommand(name, help);
  cmd->add_option("--out", common->out, fmt::format("Output directory for CSV, JSON, markdown and PNG plots (default bench/results/{})", name));
  cmd->add_option("--threads", common->threads, "Thread counts (default 1 .. all processors)")
      ->delimiter(',')
      ->check(thread_count());
  cmd->add_flag("--quick", common->quick, "Tiny fixed sizes and step counts (replacing the size flags), seconds in all: checks the pipeline (CI), measures nothing");
  commands.push_back({cmd, [common, name, action = std::move(action)] {
                        // Checked before measuring, not after: a bad --out must not cost the measurements.
                        io::ensure_writable_directory(bench::output_dir(*common, name));
                        common->command_line = command_line();
                        return action();
                      }});
  return cmd;
}

constexpr const char* kSchemesHelp =
    "subdomain, subtree, global; subdomain+paper, subtree+paper: the paper's split (subtree+parts, subtree+clusters: "
    "one of its two rules)";

}  // namespace

void add_bench_commands(CLI::App& app, Commands& commands) {
  auto* bench_cmd = app.add_subcommand("bench", "The seeds' experiments on this machine: tables, CSV, JSON and plots");
  bench_cmd->require_subcommand(1);
  auto common = std::make_shared<bench::CommonArgs>();

  auto sph = std::make_shared<bench::SphTableArgs>();
  auto* c = add_suite(bench_cmd, commands, "sph-table",
                      "SPH random box: the thesis's Tables 5.1, 5.3 and Figures 5.2, 5.3, 5.5, 5.7", common,
                      [sph, common] { return bench::run_sph_table(*sph, *common); });
  c->add_option("--sizes", sph->sizes, "Particle counts")->delimiter(',')->check(whole_number(1, kMaxCount));
  c->add_option("--neighbours", sph->neighbours, "Measured neighbours per particle to aim at")
      ->delimiter(',')
      ->check(number_in(1.0, 500.0));
  c->add_option("--strategy", sph->strategies,
                "Neighbour search(es): sph.neighbour_search values, the grid's with options, e.g. "
                "grid+morton+hashed+skin=0.1h (+rows|morton, +dense|hashed, +skin=X or Xh; default: the scene's)")
      ->delimiter(',');
  c->add_option("--settle", sph->settle, "Steps to settle the random start before timing (the thesis: 3000)")
      ->check(whole_number(0, kMaxCount));
  c->add_option("--steps", sph->steps, "Timed steps (default: about 2e6 particle-steps, 20 .. 1000)")
      ->check(whole_number(1, kMaxCount));

  auto hs = std::make_shared<bench::HashStatsArgs>();
  c = add_suite(bench_cmd, commands, "hash-stats",
                "Hash table statistics (the thesis's Table 5.2) and the cost of the duplicate check", common,
                [hs, common] { return bench::run_hash_stats(*hs, *common); });
  c->add_option("--particles", hs->particles, "Particles")->check(whole_number(1, kMaxCount));
  c->add_option("--neighbours", hs->neighbours, "Measured neighbours to aim at")->check(number_in(1.0, 500.0));
  c->add_option("--buckets", hs->buckets, "Hash table size")->check(whole_number(1, kMaxCount));
  c->add_option("--settle", hs->settle, "Steps to settle before measuring")->check(whole_number(0, kMaxCount));
  c->add_option("--steps", hs->steps, "Timed steps per setting")->check(whole_number(1, kMaxCount));

  auto bt = std::make_shared<bench::BhTableArgs>();
  c = add_suite(bench_cmd, commands, "bh-table", "Barnes-Hut: the paper's Table 2 and Figures 9-13", common,
                [bt, common] { return bench::run_bh_table(*bt, *common); });
  c->add_option("--sizes", bt->sizes, "Particle counts")->delimiter(',')->check(whole_number(1, kMaxCount));
  c->add_option("--schemes", bt->schemes, kSchemesHelp)->delimiter(',');
  c->add_option("--iterations", bt->iterations, "Iterations")->check(whole_number(1, kMaxCount));
  c->add_option("--opening", bt->opening, "Opening criterion lambda")->check(number_in(0.0, 1.0));

  auto bl = std::make_shared<bench::BhLambdaArgs>();
  c = add_suite(bench_cmd, commands, "bh-lambda", "Barnes-Hut: lambda against time and force error (Figures 14-15)",
                common, [bl, common] { return bench::run_bh_lambda(*bl, *common); });
  c->add_option("--sizes", bl->sizes, "Particle counts")->delimiter(',')->check(whole_number(1, kMaxCount));
  c->add_option("--lambdas", bl->openings, "Opening criteria")->delimiter(',')->check(number_in(0.0, 1.0));
  c->add_option("--schemes", bl->schemes, kSchemesHelp)->delimiter(',');
  c->add_option("--iterations", bl->iterations, "Iterations")->check(whole_number(1, kMaxCount));

  auto bp = std::make_shared<bench::BhPhasesArgs>();
  c = add_suite(bench_cmd, commands, "bh-phases", "Barnes-Hut: time per phase beside the paper's Table 1", common,
                [bp, common] { return bench::run_bh_phases(*bp, *common); });
  c->add_option("--sizes", bp->sizes, "Particle counts")->delimiter(',')->check(whole_number(1, kMaxCount));
  c->add_option("--schemes", bp->schemes, kSchemesHelp)->delimiter(',');
  c->add_option("--iterations", bp->iterations, "Iterations")->check(whole_number(1, kMaxCount));
  c->add_option("--opening", bp->opening, "Opening criterion lambda")->check(number_in(0.0, 1.0));

  auto bo = std::make_shared<bench::BhOptArgs>();
  c = add_suite(bench_cmd, commands, "bh-opt",
                "Barnes-Hut built at -O0, -O1, -O2, -O3: the paper's Table 2 (needs cmake --build build --target swirl_bh_opt)",
                common, [bo, common] { return bench::run_bh_opt(*bo, *common); });
  c->add_option("--sizes", bo->sizes, "Particle counts")->delimiter(',')->check(whole_number(1, kMaxCount));
  c->add_option("--schemes", bo->schemes, "subtree,subdomain,global, on the paper's tree (default subtree)")->delimiter(',');
  c->add_option("--iterations", bo->iterations, "Iterations per run (default 50 * 1024 / N, 2 .. 50)")
      ->check(whole_number(1, kMaxCount));
  c->add_option("--rounds", bo->rounds, "Runs per level, the levels alternated (medians)")->check(whole_number(1, 1000));
  c->add_option("--opening", bo->opening, "Opening criterion lambda")->check(number_in(0.0, 1.0));
  c->add_option("--bin-dir", bo->bin_dir, "Directory of swirl_bh_opt_O0 .. _O3 (default: the swirl executable's)");

  // Further suites register here (one line each).
  add_bench_bh_scale(*bench_cmd, commands);
}

}  // namespace swirl::cli
