// For tests only: failures injected into the snapshot writer (io/snapshot.hpp)
// as a full disk on one process would give them, so that the tests can check
// what every rank does when one rank's write fails inside the collective
// sequence of a parallel HDF5 file (dist/snapshot_on_ranks.hpp). The
// injected write happens (collectively, on several ranks) and then reports
// its failure, as HDF5 does when the file system refuses the data.
// Per process; nothing is injected unless a test asks.
#pragma once

namespace swirl::io::testing {

// This process's n-th dataset write from now on (1-based, counted over the
// snapshots it writes) fails; 0 cancels.
void fail_snapshot_dataset_write(int n);

}  // namespace swirl::io::testing
