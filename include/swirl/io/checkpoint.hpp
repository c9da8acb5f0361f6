// Checkpoints: everything the next step depends on, in one versioned binary
// file, so that a run stopped and resumed ends bit-identical to one that never
// stopped.
//
// Layout (little-endian), format version 4:
//   "SWIRLCKP"                          magic, 8 bytes
//   u32 version, u32 real_bytes (4 | 8), u64 particles, u64 scene_hash,
//   u64 step, f64 time
//   u32 field_count, then per field: u32 name_length, name, u32 components
//   u32 int_field_count, then per integer field: u32 name_length, name
//   u32 value_count, then per value: u32 name_length, name, f64 value
//   the real fields' data in the order listed, component by component, in
//   the particles' current memory order; then the integer fields' data (i32
//   each) in the order listed; then the ids (u64 each)
//   u64 checksum: FNV-1a 64 of every byte before it
// Fields are every real field of the ParticleSet, output and internal alike
// (positions, velocities, accelerations, previous accelerations, mass,
// density, pressure, solver fields such as "potential", and the particle
// order's reference positions when a Verlet skin is used), and every integer
// field (one std::int32_t per particle, such as a particle kind); "values"
// carry the state beyond the fields, each under its owner's prefix: the
// simulation's clock ("clock.*": the adaptive controller's previous step and
// floor), the stepper's and every solver's state ("sph.*", "self_gravity.*")
// and every observer's ("frames.*", "diagnostics.*", "checkpoints.*") and
// where the run ends ("run.end_step" or "run.end_time"; absent in files of
// earlier builds of version 2, whose resume then ends at the scene's end), so
// that a resumed run is bit-identical to one that never stopped
// (sim/simulation.hpp, sim/observer.hpp). The step and the time reached are in
// the header. Names are unique across real and integer fields.
//
// Versions:
//   4 (this one): the layout of version 3. What is new is what a file may
//     hold: a particle count other than the scene's, and ids up to and beyond
//     it, gaps where particles left (inlets and outlets change the count
//     during a run: sim/inlets_outlets.hpp), and the inlets' state among the
//     values ("inlets.<k>.layers", "inlets.next_id", "inlets.emitted",
//     "inlets.removed"). Version 3 files are still read (they come from runs
//     whose count never changed, which is what they hold).
//   3: version 2 plus the integer fields (their list after the real
//     fields', their data after the real data).
//   2: the run's values under owner prefixes, written since the
//     solver/stepper/observer seams; no integer fields (neither
//     int_field_count nor integer data). Still read: the file simply has no
//     integer fields, so a run that declares one cannot resume from it (the
//     field's values would be missing) and is refused with a message.
//   1: the layout of version 2 with unprefixed values ("frames",
//     "next_frame", ...): refused with a message saying so; resume it with the
//     swirl that wrote it.
// Whoever adds state that changes results adds it through
// save_state()/load_state() of its owner; a change of layout or of the meaning
// of a value bumps kCheckpointVersion (and says here what the old versions hold).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io {

inline constexpr std::uint32_t kCheckpointVersion = 4;                // what write_checkpoint writes
inline constexpr std::uint32_t kOldestReadableCheckpointVersion = 2;  // the oldest read_checkpoint reads

struct CheckpointHeader {
  std::uint32_t real_bytes = 8;  // 4 (float) or 8 (double)
  std::uint64_t particles = 0;
  std::uint64_t scene_hash = 0;
  std::uint64_t step = 0;
  double time = 0;
  std::uint32_t version = kCheckpointVersion;  // read: the file's; write_checkpoint always writes kCheckpointVersion
};

using CheckpointValues = std::vector<std::pair<std::string, double>>;

// The fields of a checkpoint in the file's order: every real field with its
// components, then every integer field (a ParticleSet's fields() and
// int_fields(), in that order).
struct CheckpointLayout {
  std::vector<std::pair<std::string, std::uint32_t>> fields;  // name, components
  std::vector<std::string> int_fields;

  template <class Real>
  static CheckpointLayout of(const ParticleSet<Real>& particles);
};

// Calls f(data, bytes) for every array of `particles` in the file's order (the
// order of CheckpointLayout, then the ids): what a CheckpointWriter is handed.
template <class Real, class F>
void for_each_checkpoint_array(const ParticleSet<Real>& particles, F&& f) {
  using Int = typename ParticleSet<Real>::int_type;
  const std::size_t n = particles.size();
  for (const auto& field : particles.fields())
    for (int c = 0; c < field.components; ++c) f(static_cast<const void*>(field.data[c]), n * sizeof(Real));
  for (const auto& field : particles.int_fields()) f(static_cast<const void*>(field.data[0]), n * sizeof(Int));
  f(static_cast<const void*>(particles.id.data()), n * sizeof(std::uint64_t));
}

// Writes one checkpoint piece by piece, so that neither the file nor the whole
// particle set needs to be in memory at once (on several ranks rank 0 writes
// one field of every rank at a time: dist/checkpoint_on_ranks.hpp). The
// constructor writes the header (version kCheckpointVersion, header.real_bytes
// and header.particles as given) to a temporary file beside `path`; append()
// takes the data in the file's order (each real field's components, each
// integer field, the ids: header.particles values each; an array may come in
// several pieces); finish() adds the checksum and publishes the file
// atomically and durably. Destroyed unfinished (an exception), it leaves
// `path` as it was and no temporary file. IoError for the file system's
// refusals; std::logic_error for more or less data than the header announces.
class CheckpointWriter {
 public:
  CheckpointWriter(const std::filesystem::path& path, const CheckpointHeader& header, const CheckpointLayout& layout,
                   const CheckpointValues& values);
  void append(std::string_view data);
  void finish();

 private:
  AtomicFileWriter file_;
  std::uint64_t hash_;
  std::uint64_t expected_ = 0, appended_ = 0;  // data bytes
};

// Writes a checkpoint atomically and durably (temporary file, fsync, rename).
template <class Real>
void write_checkpoint(const std::filesystem::path& path, const ParticleSet<Real>& particles,
                      const CheckpointHeader& header, const CheckpointValues& values);

// Reads only the header (for the precision); throws IoError.
CheckpointHeader read_checkpoint_header(const std::filesystem::path& path);

// Reads a checkpoint into `particles`, whose fields are matched by name: a field
// of the file missing from `particles` is added (with FieldUse::Output unless
// it was declared before); an integer field of `particles` missing from the
// file is refused (its values cannot be restored). Verifies the magic, version,
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

extern template CheckpointLayout CheckpointLayout::of<float>(const ParticleSet<float>&);
extern template CheckpointLayout CheckpointLayout::of<double>(const ParticleSet<double>&);
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
