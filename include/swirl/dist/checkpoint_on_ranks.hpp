// write_checkpoint_on_ranks: one checkpoint (io/checkpoint.hpp) of a run on
// several ranks, written by rank 0 while every rank hands it one array at a
// time (issue 19 item 6): rank 0 holds one array of the whole set at most
// (8 bytes a particle, the ids), never the whole set nor a copy of the file.
// The ranks' particles in rank order are the one-rank memory order
// (dist/key_order.hpp), so the file is the bytes io::write_checkpoint()
// writes for the whole set on one process, for any number of ranks.
//
// Collective. `path`, `header` (its scene hash, step and time; the particle
// count is the ranks' total) and `values` are rank 0's; `own` must have the
// same fields, declared in the same order, on every rank. A failure of rank
// 0's file throws io::IoError on every rank with its words, once every rank
// has handed its arrays (no rank is left waiting), and leaves `path` as it
// was and no temporary file. On one rank it is io::write_checkpoint().
#pragma once

#include <filesystem>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/io/checkpoint.hpp"

namespace swirl::dist {

template <class Real>
void write_checkpoint_on_ranks(const Communicator& comm, const std::filesystem::path& path,
                               const ParticleSet<Real>& own, const io::CheckpointHeader& header,
                               const io::CheckpointValues& values);

extern template void write_checkpoint_on_ranks<float>(const Communicator&, const std::filesystem::path&,
                                                      const ParticleSet<float>&, const io::CheckpointHeader&,
                                                      const io::CheckpointValues&);
extern template void write_checkpoint_on_ranks<double>(const Communicator&, const std::filesystem::path&,
                                                       const ParticleSet<double>&, const io::CheckpointHeader&,
                                                       const io::CheckpointValues&);

}  // namespace swirl::dist
