// The subcommands of the swirl tool. Each add_*_command() adds its CLI11
// subcommand(s) with their options to `app` and returns what to run when one
// of them was given; main() dispatches and maps exceptions to exit statuses.
// One source file per command (run_command.cpp, bench.cpp, ...).
#pragma once

#include <functional>
#include <vector>

#include <CLI/CLI.hpp>

namespace swirl::cli {

struct Command {
  CLI::App* app;                // parsed() tells whether this command was given
  std::function<int()> action;  // returns the process's exit status
  // Whether the command runs on several MPI ranks (under mpirun); the others
  // refuse to start there (run_cli.cpp).
  bool distributed = false;
};
using Commands = std::vector<Command>;

void add_run_command(CLI::App& app, Commands& commands);
void add_hash_stats_command(CLI::App& app, Commands& commands);
void add_bench_commands(CLI::App& app, Commands& commands);
// `swirl bench bh-scale` (bench_bh_scale.cpp), added to the `bench` subcommand.
void add_bench_bh_scale(CLI::App& bench_cmd, Commands& commands);
void add_info_command(CLI::App& app, Commands& commands);
void add_render_command(CLI::App& app, Commands& commands);
void add_view_command(CLI::App& app, Commands& commands);

}  // namespace swirl::cli
