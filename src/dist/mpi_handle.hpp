// The MPI communicator under a dist::Communicator, for a library that takes
// one itself (parallel HDF5: snapshot_on_ranks.cpp). Private to dist: MPI's
// header stays in communicator.cpp, so this hands out a pointer to an
// MPI_Comm, or null when the communicator is a single rank.
#pragma once

#include "swirl/dist/communicator.hpp"

namespace swirl::dist::detail {

const void* mpi_comm(const Communicator& comm);

}  // namespace swirl::dist::detail
