// `swirl info`: version, build and machine facts (for bug reports and benchmark records).
#include <omp.h>

#include <string>

#include <fmt/format.h>

#include "commands.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/config.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/sim/simd_lanes.hpp"

namespace swirl::cli {
namespace {

// Widest SIMD registers the compiler was allowed to use for the code outside
// the per-instruction-set kernels.
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
  const dist::Communicator& comm = dist::Communicator::world();
  if (!comm.is_root()) return 0;  // one rank speaks for the run
  fmt::print("swirl {}\n", SWIRL_VERSION);
  fmt::print("  git revision     {}\n", SWIRL_GIT_REVISION);
  fmt::print("  build type       {}\n", SWIRL_BUILD_TYPE);
  fmt::print("  compiler         {}\n", SWIRL_COMPILER);
  fmt::print("  OpenMP           {} (threads {}, processors {})\n", _OPENMP, omp_get_max_threads(), omp_get_num_procs());
  fmt::print("  vector width     {} bits ({} floats, {} doubles) outside the SIMD kernels\n", vector_width_bits(),
             vector_width_bits() / 32, vector_width_bits() / 64);
  // The kernels' copies (core/simd_dispatch.hpp); the active one is chosen at run time.
  std::string copies;
  for (simd::Isa isa : simd::kCompiledIsas) {
    copies += fmt::format("{}{}", copies.empty() ? "" : ", ", simd::isa_name(isa));
    copies += simd::cpu_supports(isa) ? fmt::format(" ({} floats)", sim::simd_float_lanes(isa)) : " (not on this CPU)";
  }
  fmt::print("  SIMD kernels     {} active (SWIRL_SIMD to choose); compiled: {}\n", simd::isa_name(simd::active()), copies);
  if (dist::MpiSession::built_with_mpi())
    fmt::print("  MPI              {} ({} rank{})\n", dist::MpiSession::library_version(), comm.size(),
               comm.size() == 1 ? "" : "s");
  else
    fmt::print("  MPI              not built (SWIRL_MPI=OFF)\n");
  return 0;
}

}  // namespace

void add_info_command(CLI::App& app, Commands& commands) {
  commands.push_back({app.add_subcommand("info", "Print version, build and machine facts"), [] { return print_info(); }, true});
}

}  // namespace swirl::cli
