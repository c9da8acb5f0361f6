// swirl: the command-line tool. The only place that knows about files and flags.
// run_cli() is the whole tool; main.cpp calls it, and so does the Python
// module (swirl.cli, swirl.bench and the `swirl` command a pip install adds).
//
//   swirl run SCENE [options] | swirl run --resume RUN_DIR   (run_command.cpp)
//   swirl hash-stats SCENE [options]                         (hash_stats_command.cpp)
//   swirl bench SUITE [options]                              (bench.cpp)
//   swirl info                                               (info_command.cpp)
//   swirl render RUN_DIR [options]                           (render_command.cpp)
//   swirl view SCENE [options]                               (view_command.cpp)
//
// Exit status: 0 done, 1 the run failed (blow-up, write error; render: frames
// missing), 2 bad input (every usage error, whatever CLI11's own code), 130 /
// 143 stopped by SIGINT / SIGTERM after writing a checkpoint.
//
// Under mpirun (main.cpp's MpiSession; docs/design/mpi.md): rank 0 prints;
// bad input is the same on every rank, so each rank returns 2 and rank 0 says
// why; any other error is one rank's, which prints it with its rank and ends
// every rank at once with status 1 (MPI_Abort: no rank is left waiting). A
// command not yet distributed refuses to start on several ranks.
// SWIRL_TEST_FAIL_ON_RANK=r makes rank r fail as the command starts (the
// tests' injected failure).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "run_cli.hpp"
#include "commands.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/config.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::cli {

namespace {

void inject_failure_for_tests(const dist::Communicator& comm) {
  const char* rank = std::getenv("SWIRL_TEST_FAIL_ON_RANK");
  if (rank != nullptr && std::string(rank) == std::to_string(comm.rank()))
    throw std::runtime_error("injected failure (SWIRL_TEST_FAIL_ON_RANK=" + std::string(rank) + ")");
}

}  // namespace

int run_cli(int argc, char** argv) {
  // A file-size limit must make writes fail (and the run stop cleanly), not kill us.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"swirl: particle simulation (SPH fluids, Barnes-Hut gravity)", "swirl"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("swirl ") + SWIRL_VERSION + " (" + SWIRL_GIT_REVISION + ")");

  swirl::cli::Commands commands;
  swirl::cli::add_run_command(app, commands);
  swirl::cli::add_hash_stats_command(app, commands);
  swirl::cli::add_bench_commands(app, commands);
  swirl::cli::add_info_command(app, commands);
  swirl::cli::add_render_command(app, commands);
  swirl::cli::add_view_command(app, commands);

  const dist::Communicator& comm = dist::Communicator::world();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help and the version are CLI11's to print (status 0). Every usage error
    // exits with the documented 2, not CLI11's own codes (104, 105, 109, ...).
    if (!comm.is_root()) return e.get_exit_code() == 0 ? 0 : 2;
    if (e.get_exit_code() == 0) return app.exit(e);
    fmt::print(stderr, "swirl: error: {}\nRun with --help for more information.\n", e.what());
    return 2;
  }

  try {
    // Before any parallel loop: OpenMP would start every thread OMP_NUM_THREADS asks for.
    if (const std::string w = swirl::parallel::clamp_default_thread_count(); !w.empty())
      fmt::print(stderr, "swirl: warning: {}\n", w);
    swirl::simd::active();  // a bad SWIRL_SIMD stops here, before any work
    inject_failure_for_tests(comm);
    for (const auto& command : commands) {
      if (!command.app->parsed()) continue;
      if (comm.distributed() && !command.distributed) {
        if (comm.is_root())
          fmt::print(stderr,
                     "swirl: error: `swirl {}` does not run on several MPI ranks yet ({} ranks were started); "
                     "start it without mpirun (docs/design/mpi.md says what is distributed so far)\n",
                     command.app->get_name(), comm.size());
        return 2;
      }
      return command.action();
    }
    fmt::print(stderr, "swirl: error: no command given\n");
    return 2;
  } catch (const swirl::scene::SceneError& e) {
    if (comm.is_root()) fmt::print(stderr, "swirl: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    if (comm.distributed()) {
      fmt::print(stderr, "swirl: error on rank {} of {}: {}\n", comm.rank(), comm.size(), e.what());
      std::fflush(stderr);
      comm.abort(1);
    }
    fmt::print(stderr, "swirl: error: {}\n", e.what());
    return 2;
  }
}

}  // namespace swirl::cli
