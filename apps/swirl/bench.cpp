// `swirl bench`: the seeds' performance tables, measured on this machine.
//
//   swirl bench sph      steps per second of the thesis's random box (Tables 5.1, 5.3)
//   swirl bench gravity  seconds for 50 Barnes–Hut iterations (the paper's Table 2)
#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "bench.hpp"
#include "commands.hpp"
#include "swirl/gravity/bench.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"

namespace swirl::cli {
namespace {

// The thesis's benchmark scene (examples/random_box.toml without output).
const char* kRandomBox = R"(
particles = 10000
[random_box]
neighbours = 25
[simulation]
precision = "float"
dt = 0.003
steps = 1
[box]
restitution = 0.5
[forces]
gravity = [0.0, 0.0, 0.0]
[sph]
smoothing_length = 0.05
rest_density = 1000.0
sound_speed = 3.0
viscosity = 2.0
)";

// Table 5.1 (scalar PPC 970, 15 and 25 neighbours) and Table 5.3 (Cell, 8 SPEs, 25 neighbours), Hz.
const std::map<std::size_t, std::pair<double, double>> kThesisPpc = {
    {1000, {312.5, 242.4}}, {2000, {146.2, 118.0}}, {5000, {54.2, 43.7}}, {10000, {24.1, 18.9}},
    {15000, {14.0, 11.5}},  {20000, {9.6, 7.8}},    {25000, {7.0, 5.9}},  {30000, {5.5, 4.7}},
    {35000, {4.5, 3.9}}};
const std::map<std::size_t, double> kThesisCell8 = {{1000, 545.9},  {2000, 519.2},  {5000, 252.1},
                                                    {10000, 132.7}, {15000, 87.2},  {20000, 66.3},
                                                    {25000, 53.2},  {30000, 44.5},  {35000, 38.4}};

// The paper's Table 2, -O3, seconds for 50 iterations with 1 and 8 SPEs.
const std::map<std::size_t, std::pair<double, double>> kPaperTable2 = {
    {1024, {4.18, 0.68}},   {2048, {10.73, 1.65}},   {4096, {26.49, 3.88}},
    {8192, {71.41, 9.86}}, {16384, {202.99, 27.71}}, {32768, {533.18, 72.76}}};

std::string thesis_sph(std::size_t n, double k) {
  const auto ppc = kThesisPpc.find(n);
  if (ppc == kThesisPpc.end() || (k != 15 && k != 25)) return "-";
  const double hz = k == 15 ? ppc->second.first : ppc->second.second;
  if (k == 15) return fmt::format("{:.1f} (PPC 970)", hz);
  return fmt::format("{:.1f} (PPC 970), {:.1f} (8 SPEs)", hz, kThesisCell8.at(n));
}

}  // namespace

int bench_sph_table(const BenchArgs& args) {
  fmt::print("swirl bench sph: the thesis's random box (dt = 0.003 s, h = 0.05 m), {} warm-up + {} timed steps\n",
             args.warmup, args.steps);
  fmt::print("{:>8} {:>11} {:>8} {:>10} {:>12} {:>10}   {}\n", "N", "neighbours", "threads", "steps/s", "measured k",
             "ms/step", "thesis, Hz");
  for (std::size_t n : args.particles) {
    for (double k : args.neighbours) {
      const auto scene = scene::parse_scene(
          kRandomBox, "bench", std::vector<std::string>{fmt::format("particles={}", n),
                                                        fmt::format("random_box.neighbours={}", k)});
      for (int threads : args.threads) {
        parallel::set_thread_count(threads);
        auto built = sim::build_simulation<float>(scene);
        built.sim.start();
        for (int s = 0; s < args.warmup; ++s) built.sim.step();
        double neighbours = 0;
        const auto start = std::chrono::steady_clock::now();
        for (int s = 0; s < args.steps; ++s) {
          built.sim.step();
          neighbours += built.fluid->mean_neighbors();
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        fmt::print("{:>8} {:>11} {:>8} {:>10.1f} {:>12.1f} {:>10.2f}   {}\n", n, k, threads, args.steps / seconds,
                   neighbours / args.steps, 1e3 * seconds / args.steps, thesis_sph(n, k));
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

int bench_gravity_table(const BenchArgs& args) {
  fmt::print("swirl bench gravity: Plummer sphere, lambda = {}, {} iterations, double; seconds (paper: Table 2, -O3)\n",
             args.opening, args.iterations);
  fmt::print("{:>8} {:>8} {:>10} {:>10} {:>10} {:>10} {:>11}   {}\n", "N", "threads", "scheme", "total", "tree",
             "force", "nodes/part", "paper: 1 SPE, 8 SPEs");
  for (std::size_t n : args.gravity_particles) {
    for (int threads : args.threads) {
      for (const auto& name : args.schemes) {
        gravity::BenchSettings s;
        s.scheme = gravity::parse_scheme(name);
        s.n = n;
        s.opening = args.opening;
        s.iterations = args.iterations;
        s.threads = threads;
        const auto r = gravity::time_iterations(s);
        const auto paper = kPaperTable2.find(n);
        fmt::print("{:>8} {:>8} {:>10} {:>10.3f} {:>10.3f} {:>10.3f} {:>11.0f}   {}\n", n, threads, name, r.total,
                   r.tree_build, r.force, r.mean_nodes_visited,
                   paper == kPaperTable2.end() ? std::string("-")
                                               : fmt::format("{:.2f}, {:.2f}", paper->second.first, paper->second.second));
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

void add_bench_commands(CLI::App& app, Commands& commands) {
  auto bench = std::make_shared<BenchArgs>();
  auto* bench_cmd = app.add_subcommand("bench", "Measure the seeds' performance tables on this machine");
  bench_cmd->require_subcommand(1);
  auto* bench_sph = bench_cmd->add_subcommand("sph", "Steps per second of the thesis's random box (Tables 5.1, 5.3)");
  bench_sph->add_option("--particles", bench->particles, "Particle counts")->delimiter(',');
  bench_sph->add_option("--neighbours", bench->neighbours, "Target neighbour counts")->delimiter(',');
  bench_sph->add_option("--threads", bench->threads, "Thread counts")->delimiter(',');
  bench_sph->add_option("--steps", bench->steps, "Timed steps")->check(CLI::PositiveNumber);
  bench_sph->add_option("--warmup", bench->warmup, "Steps before timing")->check(CLI::NonNegativeNumber);
  commands.push_back({bench_sph, [bench] { return bench_sph_table(*bench); }});
  auto* bench_grav = bench_cmd->add_subcommand("gravity", "Seconds for Barnes-Hut iterations (the paper's Table 2)");
  bench_grav->add_option("--particles", bench->gravity_particles, "Particle counts")->delimiter(',');
  bench_grav->add_option("--threads", bench->threads, "Thread counts")->delimiter(',');
  bench_grav->add_option("--schemes", bench->schemes, "subdomain,subtree,global")->delimiter(',');
  bench_grav->add_option("--iterations", bench->iterations, "Iterations")->check(CLI::PositiveNumber);
  bench_grav->add_option("--opening", bench->opening, "Opening criterion lambda")->check(CLI::Range(0.0, 1.0));
  commands.push_back({bench_grav, [bench] { return bench_gravity_table(*bench); }});
}

}  // namespace swirl::cli
