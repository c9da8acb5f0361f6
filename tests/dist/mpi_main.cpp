// main() of the tests in tests/dist/: GoogleTest inside an MPI session, so the
// same executable runs alone (one rank) or under mpirun (CTest runs it on 1-4
// ranks, tests/CMakeLists.txt). A test that fails on any rank fails on all:
// the exit status is the same everywhere, so mpirun reports it.
#include <gtest/gtest.h>

#include <cstdint>

#include "swirl/dist/communicator.hpp"

int main(int argc, char** argv) {
  swirl::dist::MpiSession mpi(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  const std::uint64_t failed_ranks = swirl::dist::Communicator::world().sum(std::uint64_t{status != 0});
  return failed_ranks == 0 ? 0 : 1;
}
