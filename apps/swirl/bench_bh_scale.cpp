// `swirl bench bh-scale`: the linear octree (linear_octree.hpp) from 2^12 to
// 2^23 particles, for each multipole order, opening criterion, walk (group or
// per particle), θ, bucket size, group size and precision: time per force
// evaluation (tree build + walk), interactions per second of the walk, the
// median and 99th-percentile relative force error on a random sample of
// particles against the direct sum in double (a full direct sum at 10⁶
// particles takes minutes), interactions and nodes per particle, and bytes per
// particle. The fast multipole method (fmm.hpp) is a second method on the
// same tree: for each expansion order, θ and bucket size, the same columns
// (its interactions: two per mutual M2L or particle pair; nodes: two per cell
// interaction). Time per evaluation both as wall time and as the process's
// CPU time (all threads). Tables via bench.hpp's publish().
//
//   swirl bench bh-scale [--sizes 4096,...,8388608] [--threads 1,2] [--sample 10000] [--opening 0.5,...]
//                        [--methods barnes_hut,fmm] [--fmm-orders 2,3,4,5] [--fmm-buckets 32,...]
//                        [--multipoles monopole,quadrupole] [--criteria paper,barnes] [--walks group,particle]
//                        [--bucket 16,...] [--group-sizes 64,...] [--repeats N] [--warmup N] [--precision double,float]
//                        [--out DIR] [--quick]
//
// Every list is a dimension of the table; the group size applies to the group
// walk only; multipoles, criteria and walks to Barnes–Hut, the orders to the FMM.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench.hpp"
#include "commands.hpp"
#include "flags.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/fmm.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/gravity/pair_law.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::cli {
namespace {

struct BhScaleArgs {
  std::vector<std::size_t> sizes;  // default 2^12 .. 2^23
  std::size_t sample = 10000;
  std::vector<double> openings{0.5};
  std::vector<std::string> methods{"barnes_hut", "fmm"};
  std::vector<int> fmm_orders{3};
  std::vector<std::size_t> fmm_buckets;  // empty: the --bucket list
  double softening = 0.01;
  std::vector<std::string> multipoles{"monopole", "quadrupole"};
  std::vector<std::string> criteria{"paper", "barnes"};
  std::vector<std::string> walks{"group"};
  std::vector<std::size_t> buckets{16};
  std::vector<std::size_t> group_sizes{gravity::GravitySettings{}.group_size};
  int repeats = 0;  // 0: 3 below 2^19 particles, else 1
  int warmup = 1;   // untimed evaluations first (the buffers' first touch is a run's set-up, not its steps)
  std::vector<std::string> precisions{"double"};
  std::uint64_t seed = 1;
};

std::string command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (char& c : raw)
    if (c == '\0') c = ' ';
  while (!raw.empty() && raw.back() == ' ') raw.pop_back();
  return raw.empty() ? "swirl bench bh-scale" : raw;
}

// CPU seconds of the whole process (every thread): on a shared machine the
// wall time carries the other users' load, the CPU time much less of it.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// `count` distinct particle indices, uniformly at random (partial Fisher–Yates).
std::vector<std::uint32_t> sample_indices(std::size_t n, std::size_t count, std::uint64_t seed) {
  std::vector<std::uint32_t> all(n);
  std::iota(all.begin(), all.end(), 0u);
  std::mt19937_64 rng(seed);
  count = std::min(count, n);
  for (std::size_t k = 0; k < count; ++k) {
    std::uniform_int_distribution<std::size_t> pick(k, n - 1);
    std::swap(all[k], all[pick(rng)]);
  }
  all.resize(count);
  std::sort(all.begin(), all.end());
  return all;
}

// The direct sum in double at the sampled particles: the slow twin.
template <class Real>
std::vector<std::array<double, 3>> direct_at(const ParticleSet<Real>& p, const std::vector<std::uint32_t>& at,
                                             double softening) {
  std::vector<std::array<double, 3>> out(at.size());
  const double eps2 = softening * softening;
  parallel::for_blocks("bh_scale_direct", at.size(), 16, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t k = b; k < e; ++k) {
      const std::uint32_t i = at[k];
      const double xi = p.position.x[i], yi = p.position.y[i], zi = p.position.z[i];
      gravity::Accumulator<double> acc;
      for (std::size_t j = 0; j < p.size(); ++j) {
        if (j == i) continue;
        acc.add(double(p.position.x[j]) - xi, double(p.position.y[j]) - yi, double(p.position.z[j]) - zi,
                double(p.mass[j]), eps2);
      }
      out[k] = {acc.ax, acc.ay, acc.az};
    }
  });
  return out;
}

template <class Real>
std::size_t particle_bytes(const ParticleSet<Real>& p) {
  std::size_t bytes = sizeof(std::uint64_t);
  for (const auto& f : p.fields()) bytes += std::size_t(f.components) * sizeof(Real);
  return bytes;
}

template <class Real>
void measure(const BhScaleArgs& a, const std::vector<int>& threads, bench::Table& t) {
  for (std::size_t n : a.sizes) {
    bench::progress(fmt::format("bh-scale: N = {}: Plummer sphere and the sampled direct sum", n));
    const ParticleSet<Real> p = gravity::plummer<Real>(n, a.seed);
    const auto at = sample_indices(n, a.sample, a.seed + 1);
    const int all = *std::max_element(threads.begin(), threads.end());
    parallel::set_thread_count(all);
    const auto reference = direct_at(p, at, a.softening);
    const int repeats = a.repeats > 0 ? a.repeats : (n < (std::size_t(1) << 19) ? 3 : 1);
    const std::string precision = sizeof(Real) == sizeof(float) ? "float" : "double";
    struct Point {
      std::string mp, cr, walk;
      double opening;
      std::size_t bucket, group;  // group 0: the per-particle walk (or the FMM)
      int order = 0;              // 0: Barnes–Hut; 2..5: the FMM's expansion order
    };
    std::vector<Point> points;
    for (const auto& method : a.methods) {
      if (method == "fmm") {
        for (int order : a.fmm_orders)
          for (double opening : a.openings)
            for (std::size_t bucket : a.fmm_buckets.empty() ? a.buckets : a.fmm_buckets)
              points.push_back({"-", "-", "-", opening, bucket, 0, order});
        continue;
      }
      for (const auto& mp : a.multipoles)
        for (const auto& cr : a.criteria)
          for (const auto& wk : a.walks)
            for (double opening : a.openings)
              for (std::size_t bucket : a.buckets) {
                if (wk == "particle") {
                  points.push_back({mp, cr, wk, opening, bucket, 0});
                  continue;
                }
                for (std::size_t group : a.group_sizes) points.push_back({mp, cr, wk, opening, bucket, group});
              }
    }
    for (const Point& pt : points) {
      {
        const auto& mp = pt.mp;
        const auto& cr = pt.cr;
        const bool fmm = pt.order > 0;
        gravity::GravitySettings g;
        g.scheme = gravity::Scheme::Global;
        g.tree = gravity::Tree::Linear;
        if (!fmm) {
          g.multipole = gravity::parse_multipole(mp);
          g.criterion = gravity::parse_criterion(cr);
          g.walk = gravity::parse_walk(pt.walk);
        }
        g.opening = pt.opening;
        g.softening = a.softening;
        g.bucket_size = pt.bucket;
        if (pt.group) g.group_size = pt.group;
        for (int th : threads) {
          const std::string method = fmm ? fmt::format("fmm p={}", pt.order) : std::string("barnes_hut");
          bench::progress(fmt::format("bh-scale: N = {}, {}, {}, {}, {} walk, theta {}, bucket {}, group {}, {}, {} threads",
                                      n, method, mp, cr, pt.walk, pt.opening, pt.bucket, pt.group, precision, th));
          parallel::set_thread_count(th);
          gravity::BarnesHut<Real> tree(g);
          gravity::Fmm<Real> multipole(gravity::FmmSettings{fmm ? pt.order : 3, pt.opening, a.softening, pt.bucket});
          gravity::GravityField<Real> field;
          std::vector<double> total, build, walk, cpu;
          gravity::GravityStats st;
          const auto evaluate = [&] {
            if (fmm) {
              multipole.compute(p, field, 1024);
            } else {
              tree.compute(p, field, 1024);
            }
          };
          // Untimed: allocates and touches the buffers every later evaluation reuses.
          for (int w = 0; w < a.warmup; ++w) evaluate();
          for (int r = 0; r < repeats; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            const double c0 = cpu_seconds();
            evaluate();
            total.push_back(seconds_since(t0));
            cpu.push_back(cpu_seconds() - c0);
            if (fmm) {
              // The FMM's phases in the Barnes–Hut columns: build = tree + upward pass, walk = the rest.
              const gravity::FmmStats& fs = multipole.stats();
              st = gravity::GravityStats{};
              st.mean_interactions = 2.0 * double(fs.m2l + fs.p2p_pairs) / double(n);
              st.mean_nodes_visited = 2.0 * double(fs.m2l + fs.p2p_cells) / double(n);
              st.leaves = fs.leaves;
              st.tree_bytes = fs.bytes;
              st.tree_build_seconds = fs.tree_seconds + fs.upward_seconds;
              st.force_seconds = fs.walk_seconds + fs.m2l_seconds + fs.p2p_seconds + fs.downward_seconds;
            } else {
              st = tree.stats();
            }
            build.push_back(st.tree_build_seconds);
            walk.push_back(st.force_seconds);
          }
          auto median = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            return v[v.size() / 2];
          };
          std::vector<double> err(at.size());
          for (std::size_t k = 0; k < at.size(); ++k) {
            double d2 = 0, r2 = 0;
            for (int c = 0; c < 3; ++c) {
              const double d = double(field.acceleration[c][at[k]]) - reference[k][std::size_t(c)];
              d2 += d * d;
              r2 += reference[k][std::size_t(c)] * reference[k][std::size_t(c)];
            }
            err[k] = r2 > 0 ? std::sqrt(d2 / r2) : std::sqrt(d2);
          }
          std::sort(err.begin(), err.end());
          const double tree_bpp = double(st.tree_bytes) / double(n);
          const double field_bpp = 4.0 * sizeof(Real);
          const double interactions_per_second = st.mean_interactions * double(n) / median(walk);
          t.add({bench::integer(static_cast<long long>(n)), bench::text(precision), bench::text(fmm ? "fmm" : "barnes_hut"),
                 bench::text(fmm ? std::to_string(pt.order) : "-"), bench::text(mp), bench::text(cr),
                 bench::text(pt.walk), bench::number(pt.opening, 2), bench::integer(static_cast<long long>(pt.bucket)),
                 bench::text(pt.group ? std::to_string(pt.group) : "-"),
                 bench::text(fmm ? fmt::format("{}/fmm/p{}", precision, pt.order)
                                 : fmt::format("{}/{}/{}/{}", precision, mp, cr, pt.walk)),
                 bench::integer(th),
                 bench::integer(repeats), bench::significant(1e3 * median(total), 4),
                 bench::significant(1e3 * median(cpu), 4),
                 bench::significant(1e3 * median(build), 4), bench::significant(1e3 * median(walk), 4),
                 bench::significant(1e9 * median(total) / double(n), 4),
                 bench::significant(1e-6 * interactions_per_second, 4),
                 bench::significant(err[err.size() / 2], 3),
                 bench::significant(err[std::size_t(0.99 * double(err.size() - 1))], 3),
                 bench::number(st.mean_interactions, 0), bench::number(st.mean_nodes_visited, 0),
                 bench::integer(static_cast<long long>(st.leaves)), bench::number(tree_bpp, 1),
                 bench::number(tree_bpp + field_bpp + double(particle_bytes(p)), 1),
                 bench::integer(static_cast<long long>(at.size()))});
        }
      }
    }
  }
}

int run_bh_scale(BhScaleArgs a, const bench::CommonArgs& common) {
  if (a.sizes.empty())
    for (int e = 12; e <= 23; ++e) a.sizes.push_back(std::size_t(1) << e);
  if (common.quick) {
    a.sizes = {4096, 8192};
    a.sample = 500;
    a.repeats = 1;
  }
  for (const auto& m : a.methods)  // reject unknown names before measuring
    if (m != "barnes_hut" && m != "fmm")
      throw std::invalid_argument(fmt::format("--methods: \"{}\" is neither \"barnes_hut\" nor \"fmm\"", m));
  for (int order : a.fmm_orders)
    if (order < 2 || order > 5) throw std::invalid_argument(fmt::format("--fmm-orders: {} is outside [2, 5]", order));
  for (const auto& m : a.multipoles) gravity::parse_multipole(m);
  for (const auto& c : a.criteria) gravity::parse_criterion(c);
  for (const auto& w : a.walks) gravity::parse_walk(w);
  for (const auto& p : a.precisions)
    if (p != "double" && p != "float")
      throw std::invalid_argument(fmt::format("--precision: \"{}\" is neither \"double\" nor \"float\"", p));
  const auto threads = bench::thread_counts(common);
  const int previous = parallel::thread_count();
  bench::Table t;
  auto joined = [](const auto& list) {
    std::string s;
    for (const auto& v : list) s += fmt::format("{}{}", s.empty() ? "" : ",", v);
    return s;
  };
  t.title = fmt::format("Linear octree, Barnes-Hut and FMM: time, accuracy and memory against N (θ or λ = {}, bucket {}, "
                        "group {}, FMM orders {}, {})",
                        joined(a.openings), joined(a.buckets), joined(a.group_sizes), joined(a.fmm_orders),
                        joined(a.precisions));
  t.columns = {{"particles", "N"},
               {"precision", "precision"},
               {"method", "method"},
               {"order", "FMM order p"},
               {"multipole", "multipole"},
               {"criterion", "criterion"},
               {"walk", "walk"},
               {"opening", "θ or λ"},
               {"bucket", "bucket"},
               {"group", "group"},
               {"config", "config"},
               {"threads", "threads"},
               {"repeats", "evaluations"},
               {"ms_per_evaluation", "ms / evaluation (median)"},
               {"cpu_ms_per_evaluation", "CPU ms / evaluation (median, all threads)"},
               {"ms_build", "ms build"},
               {"ms_walk", "ms walk"},
               {"ns_per_particle", "ns / particle"},
               {"minteractions_per_second", "M interactions / s (walk)"},
               {"error_median", "force error, median"},
               {"error_p99", "force error, 99th pct"},
               {"interactions", "interactions / particle"},
               {"nodes_visited", "nodes / particle"},
               {"leaves", "leaves"},
               {"tree_bytes_per_particle", "tree B / particle"},
               {"total_bytes_per_particle", "total B / particle"},
               {"sampled", "sampled"}};
  for (const auto& p : a.precisions) {
    if (p == "float")
      measure<float>(a, threads, t);
    else
      measure<double>(a, threads, t);
  }
  parallel::set_thread_count(previous);

  bench::SuiteReport r;
  r.suite = "bh-scale";
  r.title = "Barnes-Hut with the linear octree: scaling to millions of particles";
  std::string sizes;
  for (std::size_t n : a.sizes) sizes += fmt::format("{}{}", sizes.empty() ? "" : ",", n);
  r.parameters = {{"sizes", sizes},
                  {"opening", joined(a.openings)},
                  {"methods", joined(a.methods)},
                  {"fmm_orders", joined(a.fmm_orders)},
                  {"fmm_buckets", a.fmm_buckets.empty() ? joined(a.buckets) : joined(a.fmm_buckets)},
                  {"softening", fmt::format("{}", a.softening)},
                  {"walks", joined(a.walks)},
                  {"bucket", joined(a.buckets)},
                  {"group", joined(a.group_sizes)},
                  {"sample", fmt::format("{}", a.sample)},
                  {"warmup", fmt::format("{}", a.warmup)},
                  {"precision", joined(a.precisions)}};
  r.tables = {t};
  r.notes =
      "Timed evaluations follow `warmup` untimed ones on the same tree (its buffers then allocated and touched, "
      "as for every step of a run after its first). "
      "One force evaluation = tree build (Morton keys, radix sort, nodes from key prefixes, multipoles) + the "
      "walk (`group`: one walk per group of at most `group` particles, its interaction list evaluated by the SIMD "
      "kernels; `particle`: one walk per particle), on a Plummer sphere (Hénon units, ε as given). Force error: |a_tree − a_direct| / "
      "|a_direct| on a random sample of particles against the direct sum in double. Interactions: node expansions "
      "plus particle pairs per particle; M interactions / s: all of them over the walk's time. Tree B / particle: the tree's memory (nodes, sorted copies, keys, sort "
      "buffers); total adds the particle fields (ParticleSet) and the field output. `paper` = the paper's rule "
      "l/d < λ, `barnes` = Barnes' rule d > l/θ + δ (docs/gravity.md). `fmm`: the fast multipole method on the same "
      "tree (fmm.hpp), cells interacting iff r_A + r_B < θ |z_A − z_B|, expansions of order p; build = tree + "
      "multipoles, walk = dual walk + M2L + P2P + L2L/L2P; interactions = 2 × (M2L + particle pairs) / N "
      "(every interaction is mutual), nodes = 2 × cell interactions / N.";
  bench::PlotPanel time;
  time.x = "particles";
  time.xlabel = "N";
  time.ylabel = "ms per force evaluation";
  time.logx = time.logy = true;
  time.complexity_guides = true;
  time.series.push_back({"", "ms_per_evaluation", "", {}, "config"});
  bench::PlotPanel err;
  err.x = "particles";
  err.xlabel = "N";
  err.ylabel = "relative force error, 99th percentile";
  err.logx = err.logy = true;
  err.series.push_back({"", "error_p99", "", {}, "config"});
  r.plots = {{"bh_scale.png", "Linear octree: time and accuracy against N", {time, err}}};
  return bench::publish(r, common);
}

}  // namespace

void add_bench_bh_scale(CLI::App& bench_cmd, Commands& commands) {
  auto args = std::make_shared<BhScaleArgs>();
  auto common = std::make_shared<bench::CommonArgs>();
  auto* c = bench_cmd.add_subcommand("bh-scale", "Barnes-Hut and the FMM on the linear octree from 2^12 to 2^23 "
                                                 "particles: time, sampled force error, interactions and bytes per particle");
  c->add_option("--sizes", args->sizes, "Particle counts (default 4096,...,8388608)")
      ->delimiter(',')
      ->check(whole_number(1, kMaxCount));
  c->add_option("--threads", common->threads, "Thread counts (default 1 .. all processors)")
      ->delimiter(',')
      ->check(thread_count());
  c->add_option("--sample", args->sample, "Particles sampled for the force error")->check(whole_number(1, kMaxCount));
  c->add_option("--opening", args->openings, "theta (barnes) or lambda (paper); a list is a dimension")
      ->delimiter(',')
      ->check(number_in(0.0, 1.0));
  c->add_option("--softening", args->softening, "epsilon")->check(non_negative_finite());
  c->add_option("--methods", args->methods, "barnes_hut,fmm (default both)")->delimiter(',');
  c->add_option("--fmm-orders", args->fmm_orders, "FMM expansion orders p in [2, 5] (default 3)")->delimiter(',');
  c->add_option("--fmm-buckets", args->fmm_buckets, "FMM leaf sizes (default: the --bucket list)")
      ->delimiter(',')
      ->check(whole_number(1, kMaxCount));
  c->add_option("--multipoles", args->multipoles, "monopole,quadrupole")->delimiter(',');
  c->add_option("--criteria", args->criteria, "paper,barnes")->delimiter(',');
  c->add_option("--walks", args->walks, "group,particle (default group)")->delimiter(',');
  c->add_option("--bucket", args->buckets, "Particles per leaf at most (a list is a dimension)")
      ->delimiter(',')
      ->check(whole_number(1, kMaxCount));
  c->add_option("--group-sizes", args->group_sizes, "Group walk: particles per group at most (default: GravitySettings, 256)")
      ->delimiter(',')
      ->check(whole_number(1, kMaxCount));
  c->add_option("--repeats", args->repeats, "Timed evaluations per point (default 3 below 2^19, else 1)")
      ->check(whole_number(1, kMaxCount));
  c->add_option("--warmup", args->warmup,
                "Untimed evaluations before the timed ones, on the same tree (default 1: the first evaluation's "
                "allocations and page faults are a run's set-up, not its steps; 0 times a cold start)")
      ->check(whole_number(0, 100));
  c->add_option("--precision", args->precisions, "double,float (default double)")->delimiter(',');
  c->add_option("--seed", args->seed, "Seed of the Plummer sphere and the sample");
  c->add_option("--out", common->out, "Output directory for CSV, JSON, markdown and PNG plots (default bench/bh-scale)");
  c->add_flag("--quick", common->quick, "Tiny sizes: checks the pipeline (CI), measures nothing");
  commands.push_back({c, [args, common] {
                        io::ensure_writable_directory(bench::output_dir(*common, "bh-scale"));
                        common->command_line = command_line();
                        return run_bh_scale(*args, *common);
                      }});
}

}  // namespace swirl::cli
