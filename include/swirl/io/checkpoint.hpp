// Checkpoints: everything the next step depends on, in one versioned binary
// file, so that a run stopped and resumed ends bit-identical to one that never
// stopped.
//
// Layout (little-endian), format version 1:
//   "SWIRLCKP"                          magic, 8 bytes
//   u32 version, u32 real_bytes (4 | 8), u64 particles, u64 scene_hash,
//   u64 step, f64 time
//   u32 field_count, then per field: u32 name_length, name, u32 components
//   u32 value_count, then per value: u32 name_length, name, f64 value
//   the fields' data in the order listed, component by component, in the
//   particles' current memory order; then the ids (u64 each)
//   u64 checksum: FNV-1a 64 of every byte before it
// Fields are every real field of the ParticleSet (positions, velocities,
// accelerations, previous accelerations, mass, density, pressure, solver
// fields such as "potential"); "values" carry run and solver state (frames
// written, the next output time, the initial energy, ...). No solver holds
// state that changes results today: SPH rebuilds its hash and lists every step,
// and the gravity sub-domain load balance (nodes explored last step) decides
// only which thread walks which tree, never a particle's summation order, so a
// resumed run is bit-identical without it (tested). Adaptive time steps keep
// their controller's state (dt_previous, dt_floor) and the step history of the
// current frame among the values, and the time reached in the header; the
// format is unchanged, and run_scene refuses to resume an adaptive run from a
// checkpoint without those values. Whoever adds state
// that changes results adds it here and bumps kCheckpointVersion; older
// versions are refused with a message saying so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "swirl/core/particle_set.hpp"

namespace swirl::io {

inline constexpr std::uint32_t kCheckpointVersion = 1;

struct CheckpointHeader {
  std::uint32_t real_bytes = 8;  // 4 (float) or 8 (double)
  std::uint64_t particles = 0;
  std::uint64_t scene_hash = 0;
  std::uint64_t step = 0;
  double time = 0;
};

using CheckpointValues = std::vector<std::pair<std::string, double>>;

// Writes a checkpoint atomically and durably (temporary file, fsync, rename).
template <class Real>
void write_checkpoint(const std::filesystem::path& path, const ParticleSet<Real>& particles,
                      const CheckpointHeader& header, const CheckpointValues& values);

// Reads only the header (for the precision); throws IoError.
CheckpointHeader read_checkpoint_header(const std::filesystem::path& path);

// Reads a checkpoint into `particles`, whose fields are matched by name: a field
// of the file missing from `particles` is added. Verifies the magic, version,
// precision, sizes and checksum first; throws IoError naming the file and the
// reason, and never allocates more than the file's size justifies.
template <class Real>
CheckpointHeader read_checkpoint(const std::filesystem::path& path, ParticleSet<Real>& particles,
                                 CheckpointValues& values);

// Parses checkpoint bytes already in memory (`name` is used in messages): the
// entry point of read_checkpoint and of the fuzzer.
template <class Real>
CheckpointHeader parse_checkpoint(std::string_view bytes, std::string_view name, ParticleSet<Real>& particles,
                                  CheckpointValues& values);

extern template void write_checkpoint<float>(const std::filesystem::path&, const ParticleSet<float>&,
                                             const CheckpointHeader&, const CheckpointValues&);
extern template void write_checkpoint<double>(const std::filesystem::path&, const ParticleSet<double>&,
                                              const CheckpointHeader&, const CheckpointValues&);
extern template CheckpointHeader read_checkpoint<float>(const std::filesystem::path&, ParticleSet<float>&,
                                                        CheckpointValues&);
extern template CheckpointHeader read_checkpoint<double>(const std::filesystem::path&, ParticleSet<double>&,
                                                         CheckpointValues&);
extern template CheckpointHeader parse_checkpoint<float>(std::string_view, std::string_view, ParticleSet<float>&,
                                                         CheckpointValues&);
extern template CheckpointHeader parse_checkpoint<double>(std::string_view, std::string_view, ParticleSet<double>&,
                                                          CheckpointValues&);

}  // namespace swirl::io
