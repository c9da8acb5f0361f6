// For tests only: failures injected into the snapshot writer (io/snapshot.hpp)
// and the checkpoint writer (io/checkpoint.hpp) as a full disk on one process
// would give them, so that the tests can check what every rank does when one
// rank's write fails inside a collective sequence: a parallel HDF5 file
// (dist/snapshot_on_ranks.hpp), a checkpoint that rank 0 writes while the
// ranks hand it their fields one at a time (dist/checkpoint_on_ranks.hpp).
// The injected write happens and then reports its failure, as HDF5 or the
// file system does when the disk refuses the data.
// Per process; nothing is injected unless a test asks.
#pragma once

namespace swirl::io::testing {

// This process's n-th dataset write from now on (1-based, counted over the
// snapshots it writes) fails; 0 cancels.
void fail_snapshot_dataset_write(int n);

// This process's n-th checkpoint data append from now on (1-based, counted
// over the checkpoints it writes: CheckpointWriter::append) writes its bytes,
// then fails as a full disk would; 0 cancels.
void fail_checkpoint_append(int n);

}  // namespace swirl::io::testing
