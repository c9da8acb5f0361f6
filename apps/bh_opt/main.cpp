// swirl_bh_opt_O<level>: one run of the paper's Table 2 experiment (Demiroz
// et al. 2011, section 5) from a build at one optimisation level. CMake builds
// this file and the whole gravity module four times, at -O0 .. -O3
// (apps/bh_opt/CMakeLists.txt); `swirl bench bh-opt` runs the four programs
// and sets their times side by side.
//
// The run is gravity::time_iterations, the harness `swirl bench bh-table`
// times: a Plummer sphere, then `iterations` steps of force evaluation on the
// paper's insertion-built octree + leapfrog update, in double.
//
//   swirl_bh_opt_O2 --scheme subtree --particles 4096 --iterations 10 [--threads 1] [--opening 0.5] [--seed 1]
//
// Prints two CSV lines on stdout: the column names and the run. Errors go to
// stderr with exit status 2.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>

#include "swirl/gravity/bench.hpp"
#include "swirl/gravity/settings.hpp"

#ifndef SWIRL_BH_OPT_LEVEL
#error "SWIRL_BH_OPT_LEVEL (0..3) is set by apps/bh_opt/CMakeLists.txt"
#endif
// The one check the preprocessor can make that the level asked for is the
// level compiled: GCC and Clang define __OPTIMIZE__ at -O1 and above only.
#if (SWIRL_BH_OPT_LEVEL == 0) == defined(__OPTIMIZE__)
#error "the -O flag on the command line is not the one SWIRL_BH_OPT_LEVEL names (a build type's -O leaked in?)"
#endif

namespace {

#if defined(__clang__)
constexpr const char* kCompiler = "clang " __clang_version__;
#elif defined(__GNUC__)
constexpr const char* kCompiler = "g++ " __VERSION__;
#else
constexpr const char* kCompiler = "unknown";
#endif

template <class T>
T parse_number(std::string_view flag, std::string_view text) {
  T value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size())
    throw std::invalid_argument(std::string(flag) + ": \"" + std::string(text) + "\" is not a number");
  return value;
}

int run(int argc, char** argv) {
  swirl::gravity::BenchSettings s;
  s.scheme = swirl::gravity::Scheme::Subtree;
  s.threads = 1;
  std::string scheme = "subtree";
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (i + 1 >= argc) throw std::invalid_argument(std::string(flag) + " needs a value");
    const std::string_view value = argv[++i];
    if (flag == "--scheme") {
      s.scheme = swirl::gravity::parse_scheme(value);  // throws with the allowed names
      scheme = value;
    } else if (flag == "--particles") {
      s.n = parse_number<std::size_t>(flag, value);
    } else if (flag == "--iterations") {
      s.iterations = parse_number<int>(flag, value);
    } else if (flag == "--threads") {
      s.threads = parse_number<int>(flag, value);
    } else if (flag == "--opening") {
      s.opening = parse_number<double>(flag, value);
      if (!(s.opening >= 0 && s.opening <= 1)) throw std::invalid_argument("--opening: lambda must be in [0, 1]");
    } else if (flag == "--seed") {
      s.seed = parse_number<std::uint64_t>(flag, value);
    } else {
      throw std::invalid_argument("unknown option " + std::string(flag) +
                                  " (--scheme, --particles, --iterations, --threads, --opening, --seed)");
    }
  }
  const swirl::gravity::BenchResult r = swirl::gravity::time_iterations(s);  // checks n, iterations, threads
  std::printf(
      "level,compiler,scheme,particles,threads,iterations,opening,seconds,tree_seconds,force_seconds,update_seconds,"
      "nodes_visited,trees\n");
  std::printf("O%d,\"%s\",%s,%zu,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%zu\n", SWIRL_BH_OPT_LEVEL, kCompiler,
              scheme.c_str(), s.n, s.threads, s.iterations, s.opening, r.total, r.tree_build, r.force, r.update,
              r.mean_nodes_visited, r.trees);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argc > 0 ? argv[0] : "swirl_bh_opt", e.what());
    return 2;
  }
}
