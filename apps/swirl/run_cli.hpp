// The whole swirl command-line tool as one function: parses argv (argv[0] is
// the program name), runs the command and returns the exit status (main.cpp's
// table: 0 done, 1 the run failed, 2 bad input, 130/143 stopped by a signal).
// Errors are printed to stderr, never thrown. The executable's main() and the
// Python module (swirl.cli, swirl.bench, the `swirl` command pip installs)
// call it. What it leaves changed in the process: the SIGINT/SIGTERM handlers
// (`swirl run` installs its own) and the thread count (--threads, the bench
// suites); a caller that lives on restores them (python/src/cli.cpp).
#pragma once

namespace swirl::cli {

int run_cli(int argc, char** argv);

}  // namespace swirl::cli
