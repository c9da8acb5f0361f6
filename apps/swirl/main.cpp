// swirl: the command-line tool (run_cli.cpp is all of it; the Python module
// calls the same function).
#include "run_cli.hpp"

int main(int argc, char** argv) { return swirl::cli::run_cli(argc, argv); }
