// swirl: the command-line tool (run_cli.cpp is all of it; the Python module
// calls the same function). Under mpirun the process is one rank of a run:
// MPI lives exactly as long as main (dist/communicator.hpp).
#include "run_cli.hpp"
#include "swirl/dist/communicator.hpp"

int main(int argc, char** argv) {
  const swirl::dist::MpiSession mpi(argc, argv);
  return swirl::cli::run_cli(argc, argv);
}
