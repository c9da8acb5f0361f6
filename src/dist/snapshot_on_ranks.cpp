#include "swirl/dist/snapshot_on_ranks.hpp"

#include <string>
#include <vector>
#include <system_error>

#include "mpi_handle.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::dist {

template <class Real>
io::SnapshotLayout write_snapshot_on_ranks(const Communicator& comm, const std::filesystem::path& path,
                                           const ParticleSet<Real>& own, const io::SnapshotInfo& info,
                                           io::ParticleRows rows) {
  if (!comm.distributed()) return io::write_snapshot(path, own, info, rows);
  const std::uint64_t mine = rows ? rows->size() : own.size();
  io::SnapshotPart part;
  part.mpi_comm = detail::mpi_comm(comm);
  const std::vector<std::uint64_t> counts = comm.all_gather(mine);  // every rank's rows: one collective
  for (int r = 0; r < comm.size(); ++r) {
    if (r < comm.rank()) part.first += counts[std::size_t(r)];
    part.total += counts[std::size_t(r)];
  }
  std::string error;
  if (comm.is_root()) {
    try {
      part.file = io::temporary_sibling(path);
    } catch (const io::IoError& e) {
      error = e.what();
    }
  }
  // Rank 0's failure to name the temporary file, or the name, on every rank.
  error = comm.first_text(error);
  if (!error.empty()) throw io::IoError(error);
  part.file = comm.first_text(comm.is_root() ? part.file.string() : std::string());
  io::SnapshotLayout layout;
  try {
    layout = io::write_snapshot_part(part, path, own, info, rows);
  } catch (const io::IoError& e) {
    error = e.what();
  }
  error = comm.first_text(error);  // every rank has closed the file here
  if (error.empty() && comm.is_root()) {
    try {
      io::publish_file_atomic(part.file, path);
    } catch (const io::IoError& e) {
      error = e.what();
    }
  }
  error = comm.first_text(error);
  if (!error.empty()) {
    if (comm.is_root()) {
      std::error_code ignored;
      std::filesystem::remove(part.file, ignored);
    }
    throw io::IoError(error);
  }
  return layout;
}

template io::SnapshotLayout write_snapshot_on_ranks<float>(const Communicator&, const std::filesystem::path&,
                                                           const ParticleSet<float>&, const io::SnapshotInfo&,
                                                           io::ParticleRows);
template io::SnapshotLayout write_snapshot_on_ranks<double>(const Communicator&, const std::filesystem::path&,
                                                            const ParticleSet<double>&, const io::SnapshotInfo&,
                                                            io::ParticleRows);

}  // namespace swirl::dist
