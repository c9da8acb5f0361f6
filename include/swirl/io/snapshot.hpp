// HDF5 snapshots: one frame per file, in the layout the Gadget-format HDF5
// codes share (Gadget-2/4, AREPO and SWIFT write it; yt, pynbody and the
// community's initial-condition generators read or write it), so swirl's
// frames open in those tools and their files can be read back here.
//
// Layout (format version kSnapshotVersion):
//   /Header                attributes: NumPart_ThisFile, NumPart_Total,
//                          NumPart_Total_HighWord (6 × uint32, the count in the
//                          particle type's slot), MassTable (6 × double, all 0:
//                          masses are per particle), Time, Redshift (0),
//                          BoxSize (the box's largest side; 0 without walls),
//                          NumFilesPerSnapshot (1), Flag_DoublePrecision;
//                          swirl's own: SwirlFormatVersion, UnitSystem ("si" |
//                          "nbody"), GravitationalConstant (in the run's units).
//   /Units                 SI runs only, SWIFT's attribute names: "Unit length
//                          in cgs (U_L)" = 100, mass (U_M) = 1000, time (U_t) =
//                          1, current (U_I) = 1, temperature (U_T) = 1.
//   /PartType<k>           k = 0 for SPH fluid, 1 for collisionless particles
//                          (stars, dark matter), 2 for boundary particles
//                          (their own files, boundary_NNNNNN.h5: see
//                          io/frame_names.hpp; Gadget's slot 2 is free for
//                          this, its "disk" only by convention): datasets Coordinates (N × 3),
//                          Velocities (N × 3), Masses (N), ParticleIDs (N,
//                          uint64), then every other output field of the
//                          ParticleSet (the built-ins by their Gadget names:
//                          Accelerations, Density, Pressure; the others, e.g.
//                          potential, by their own names), real fields in the
//                          run's precision, integer fields as int32; each with
//                          an attribute "units" naming its unit in words.
// Datasets are chunked (65 536 rows a chunk) and deflated (with the shuffle
// filter), their chunks allocated when they are created; object times are not
// recorded, so the same state gives the same bytes, written by one process or
// by the ranks of a run (parallel HDF5).
//
// Reading accepts any file with that layout (masses either per particle or
// from MassTable) and refuses anything else with an IoError naming the file
// and the group, dataset or attribute, and the reason: missing, wrong shape or
// type, a count that disagrees with the header, a value that is not finite,
// one part of a snapshot split over several files (NumFilesPerSnapshot > 1).
// One particle type is read at a time: the one asked for (any of Gadget's six,
// as initial-condition files split a galaxy into halo, disk and bulge types),
// or else the only type 0 or 1 the file has particles of.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "swirl/core/particle_set.hpp"

namespace swirl::io {

inline constexpr int kSnapshotVersion = 1;

// Gadget's particle types that swirl writes. A file read may hold any of the
// six (0 to 5; kGadgetTypes), which read_snapshot reports as PartType(k).
enum class PartType : int { Gas = 0, Collisionless = 1, Boundary = 2 };
inline constexpr int kGadgetTypes = 6;

// What a snapshot says beside its particles.
struct SnapshotInfo {
  double time = 0;
  PartType type = PartType::Gas;
  double box_size = 0;          // the box's largest side (0: no walls)
  bool si_units = true;         // false: N-body units (G = 1 by default)
  double gravitational_constant = 6.6743e-11;
};

// What a snapshot file holds, without its values: enough to describe it to
// ParaView (io/xdmf.hpp).
struct SnapshotLayout {
  struct Dataset {
    std::string name;      // in /PartType<k>
    int components = 1;    // columns
    bool integer = false;  // stored as an integer type
    bool is_unsigned = false;  // an unsigned integer (ParticleIDs)
    int bytes = 8;         // bytes per value
  };
  double time = 0;
  PartType type = PartType::Gas;
  std::size_t count = 0;
  std::vector<Dataset> datasets;  // in file order: Coordinates, Velocities, Masses, ParticleIDs, ...
};

// Which particles of a set a file holds: the set's indices `rows`, in that
// order (a frame series of one particle kind); nullopt: all, in memory order.
using ParticleRows = std::optional<std::span<const std::size_t>>;

// Writes one frame atomically (built in memory, then io::write_file_atomic)
// and returns what it wrote.
template <class Real>
SnapshotLayout write_snapshot(const std::filesystem::path& path, const ParticleSet<Real>& particles,
                              const SnapshotInfo& info, ParticleRows rows = std::nullopt);

// One process's part of a snapshot that several write together (parallel
// HDF5's MPI-IO driver; builds with MPI only: SWIRL_PARALLEL_HDF5). Every
// process of the communicator calls write_snapshot_part() with the same
// `file`, `total` and info (collective), each its own rows, which are rows
// [first, first + its count) of the file; the file holds the bytes
// write_snapshot() gives for the whole set on one process (every dataset's
// chunks are allocated when it is created, as parallel HDF5 requires, in
// both). The caller names the file, makes it public (a temporary file renamed
// once every process has returned) and agrees on failures:
// dist::write_snapshot_on_ranks() does all that. Throws IoError naming
// `path_in_messages` on the process that failed.
struct SnapshotPart {
  const void* mpi_comm = nullptr;  // points to an MPI_Comm (dist: src/dist/mpi_handle.hpp)
  std::filesystem::path file;      // where they write
  std::uint64_t first = 0, total = 0;
};

template <class Real>
SnapshotLayout write_snapshot_part(const SnapshotPart& part, const std::filesystem::path& path_in_messages,
                                   const ParticleSet<Real>& particles, const SnapshotInfo& info,
                                   ParticleRows rows = std::nullopt);

extern template SnapshotLayout write_snapshot<float>(const std::filesystem::path&, const ParticleSet<float>&,
                                                     const SnapshotInfo&, ParticleRows);
extern template SnapshotLayout write_snapshot<double>(const std::filesystem::path&, const ParticleSet<double>&,
                                                      const SnapshotInfo&, ParticleRows);
extern template SnapshotLayout write_snapshot_part<float>(const SnapshotPart&, const std::filesystem::path&,
                                                          const ParticleSet<float>&, const SnapshotInfo&, ParticleRows);
extern template SnapshotLayout write_snapshot_part<double>(const SnapshotPart&, const std::filesystem::path&,
                                                           const ParticleSet<double>&, const SnapshotInfo&,
                                                           ParticleRows);

// The layout of a snapshot file, from its header and dataset shapes only (no
// values read), for the particle type asked for or as read_snapshot chooses.
// Throws IoError as read_snapshot does for what it looks at.
SnapshotLayout read_snapshot_layout(const std::filesystem::path& path, std::optional<int> part_type = std::nullopt);

// One dataset read back: `columns` values per particle, row by row, in double
// (integer datasets converted exactly below 2⁵³).
struct SnapshotDataset {
  std::size_t columns = 1;
  bool integer = false;       // stored as an integer type
  std::string units;          // its "units" attribute, if any
  std::vector<double> values;  // rows × columns
};

// A /Units group's scale factors (SWIFT's names, "Unit length in cgs (U_L)",
// ...): how many cm, g and s one unit of the file's length, mass and time is.
struct CgsUnits {
  double length = 0;  // U_L, cm
  double mass = 0;    // U_M, g
  double time = 0;    // U_t, s
};

struct SnapshotFile {
  SnapshotInfo info;
  int version = 0;                         // SwirlFormatVersion; 0 for files from other codes
  std::string unit_system;                 // /Header/UnitSystem as written ("si", "nbody"); "" when absent
  std::optional<CgsUnits> cgs_units;       // /Units; nullopt when the file has no such group
  std::size_t count = 0;                   // particles of the one type present
  std::vector<std::uint64_t> ids;          // ParticleIDs (0..count−1 when absent)
  std::map<std::string, SnapshotDataset> datasets;  // by name; Coordinates, Velocities, Masses always present
};

// Particles of each Gadget type, from /Header/NumPart_ThisFile (the header
// only: no group or dataset is looked at). Throws IoError.
std::array<std::uint64_t, kGadgetTypes> snapshot_particle_counts(const std::filesystem::path& path);

// Reads a snapshot (see the header comment): the particles of `part_type`
// (0 to 5) when given, else of the only type the file has particles of (0 or
// 1; a file with several is refused). Throws IoError.
SnapshotFile read_snapshot(const std::filesystem::path& path, std::optional<int> part_type = std::nullopt);

}  // namespace swirl::io
