#include "swirl/dist/checkpoint_on_ranks.hpp"

#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/io/atomic_file.hpp"

namespace swirl::dist {

template <class Real>
void write_checkpoint_on_ranks(const Communicator& comm, const std::filesystem::path& path,
                               const ParticleSet<Real>& own, const io::CheckpointHeader& header,
                               const io::CheckpointValues& values) {
  if (!comm.distributed()) {
    io::write_checkpoint(path, own, header, values);
    return;
  }
  io::CheckpointHeader whole = header;
  whole.real_bytes = sizeof(Real);
  whole.particles = comm.sum(std::uint64_t{own.size()});
  std::optional<io::CheckpointWriter> out;
  std::string error;
  if (comm.is_root()) {
    try {
      out.emplace(path, whole, io::CheckpointLayout::of(own), values);
    } catch (const io::IoError& e) {
      error = e.what();
    }
  }
  // A file rank 0 cannot even open: no array need travel.
  error = comm.first_text(error);
  if (!error.empty()) throw io::IoError(error);

  // Every array in the file's order, each rank's share in rank order; after a
  // failed append rank 0 still takes the arrays (the others are in the gather).
  Bytes mine;
  io::for_each_checkpoint_array(own, [&](const void* data, std::size_t bytes) {
    mine.resize(bytes);
    if (bytes > 0) std::memcpy(mine.data(), data, bytes);
    const std::vector<Bytes> shares = comm.gather_to_root(mine);
    if (!out) return;
    try {
      for (const Bytes& share : shares)
        out->append(std::string_view(reinterpret_cast<const char*>(share.data()), share.size()));
    } catch (const io::IoError& e) {
      error = e.what();
      out.reset();  // the temporary file is removed
    }
  });
  if (out) {
    try {
      out->finish();
    } catch (const io::IoError& e) {
      error = e.what();
    }
    out.reset();
  }
  error = comm.first_text(error);
  if (!error.empty()) throw io::IoError(error);
}

template void write_checkpoint_on_ranks<float>(const Communicator&, const std::filesystem::path&,
                                               const ParticleSet<float>&, const io::CheckpointHeader&,
                                               const io::CheckpointValues&);
template void write_checkpoint_on_ranks<double>(const Communicator&, const std::filesystem::path&,
                                                const ParticleSet<double>&, const io::CheckpointHeader&,
                                                const io::CheckpointValues&);

}  // namespace swirl::dist
