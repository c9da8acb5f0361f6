// `swirl info`: version, build and machine facts (for bug reports and benchmark records).
#include <omp.h>

#include <fmt/format.h>

#include "commands.hpp"
#include "swirl/config.hpp"

namespace swirl::cli {
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

}  // namespace

void add_info_command(CLI::App& app, Commands& commands) {
  commands.push_back({app.add_subcommand("info", "Print version, build and machine facts"), [] { return print_info(); }});
}

}  // namespace swirl::cli
