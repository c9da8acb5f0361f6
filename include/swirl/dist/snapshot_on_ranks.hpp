// write_snapshot_on_ranks: one HDF5 snapshot (io/snapshot.hpp) written by the
// ranks of a run together (issue 19 item 6), so that no rank holds the whole
// set to write a frame: each rank passes its own particles (the `rows` of
// them, a frame series of one kind), which are the file's rows in rank order
// (the ranks' shares of the global key order: the one-rank memory order).
//
// Collective. On several ranks rank 0 names a temporary file beside `path`,
// every rank writes its hyperslab into it through parallel HDF5
// (io::write_snapshot_part, collective I/O), and rank 0 renames it over `path`
// once every rank has closed it: the file is the bytes io::write_snapshot()
// writes for the whole set on one process, for any number of ranks. A
// failure on any rank throws io::IoError on every rank with the words of the
// lowest failing rank and leaves `path` as it was. On one rank it is
// io::write_snapshot(). `path` and `info` must be the same on every rank;
// HDF5's own messages are not counted in the communicator's traffic().
#pragma once

#include <filesystem>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/io/snapshot.hpp"

namespace swirl::dist {

template <class Real>
io::SnapshotLayout write_snapshot_on_ranks(const Communicator& comm, const std::filesystem::path& path,
                                           const ParticleSet<Real>& own, const io::SnapshotInfo& info,
                                           io::ParticleRows rows = std::nullopt);

extern template io::SnapshotLayout write_snapshot_on_ranks<float>(const Communicator&, const std::filesystem::path&,
                                                                  const ParticleSet<float>&, const io::SnapshotInfo&,
                                                                  io::ParticleRows);
extern template io::SnapshotLayout write_snapshot_on_ranks<double>(const Communicator&, const std::filesystem::path&,
                                                                   const ParticleSet<double>&, const io::SnapshotInfo&,
                                                                   io::ParticleRows);

}  // namespace swirl::dist
