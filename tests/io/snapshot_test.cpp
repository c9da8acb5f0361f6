// HDF5 snapshots (io/snapshot.hpp): every field round-trips exactly, the same
// state gives the same bytes, files written by an independent writer (h5py,
// tests/io/gadget_files.py) are read one particle type at a time with their
// unit attributes reported, and bad files are refused naming the
// dataset.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <string>

#include "io/io_test_util.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/snapshot.hpp"

namespace swirl::io {
namespace {

using test::TempDir;

template <class Real>
class SnapshotTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SnapshotTest, Precisions);

// The dataset a field is written to (snapshot.hpp: Gadget names for the built-ins).
std::string dataset_of(std::string_view field) {
  if (field == "position") return "Coordinates";
  if (field == "velocity") return "Velocities";
  if (field == "acceleration") return "Accelerations";
  if (field == "mass") return "Masses";
  if (field == "density") return "Density";
  if (field == "pressure") return "Pressure";
  return std::string(field);
}

TYPED_TEST(SnapshotTest, EveryOutputFieldRoundTripsExactly) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = test::make_particles<Real>(1000);
  SnapshotInfo info;
  info.time = 1.25;
  info.type = PartType::Gas;
  info.box_size = 3.5;
  write_snapshot(dir / "s.h5", p, info);
  const SnapshotFile s = read_snapshot(dir / "s.h5");
  EXPECT_EQ(s.version, kSnapshotVersion);
  EXPECT_EQ(s.count, p.size());
  EXPECT_EQ(s.info.time, 1.25);
  EXPECT_EQ(s.info.box_size, 3.5);
  EXPECT_EQ(s.info.type, PartType::Gas);
  EXPECT_TRUE(s.info.si_units);
  EXPECT_EQ(s.ids, std::vector<std::uint64_t>(p.id.begin(), p.id.end()));
  std::size_t checked = 0;
  for (const auto& f : p.fields()) {
    const auto it = s.datasets.find(dataset_of(f.name));
    if (f.internal) {
      EXPECT_EQ(it, s.datasets.end()) << f.name << " is internal";
      continue;
    }
    ASSERT_NE(it, s.datasets.end()) << f.name;
    ASSERT_EQ(it->second.columns, std::size_t(f.components)) << f.name;
    EXPECT_FALSE(it->second.integer);
    const auto expected = test::interleaved(f, p.size());
    std::vector<Real> got(it->second.values.begin(), it->second.values.end());  // exact: stored as Real
    EXPECT_EQ(test::bytes_of(got), test::bytes_of(expected)) << f.name;
    ++checked;
  }
  EXPECT_GE(checked, 7u);
  const auto& kind = s.datasets.at("kind");
  EXPECT_TRUE(kind.integer);
  for (std::size_t i = 0; i < p.size(); ++i) ASSERT_EQ(kind.values[i], double(p.int_field(0)[i])) << i;
  EXPECT_EQ(s.datasets.at("Coordinates").units, "m");
  EXPECT_EQ(s.datasets.at("Velocities").units, "m/s");
}

TYPED_TEST(SnapshotTest, TheSameStateGivesTheSameBytesAndNbodyUnitsAreSaid) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = test::make_particles<Real>(300);
  SnapshotInfo info;
  info.type = PartType::Collisionless;
  info.si_units = false;
  info.gravitational_constant = 1;
  write_snapshot(dir / "a.h5", p, info);
  write_snapshot(dir / "b.h5", p, info);
  EXPECT_EQ(test::slurp(dir / "a.h5"), test::slurp(dir / "b.h5"));
  const SnapshotFile s = read_snapshot(dir / "a.h5");
  EXPECT_EQ(s.info.type, PartType::Collisionless);
  EXPECT_FALSE(s.info.si_units);
  EXPECT_EQ(s.info.gravitational_constant, 1.0);
  EXPECT_EQ(s.datasets.at("Coordinates").units, "length");
  // A different state gives different bytes (the comparison can fail).
  auto q = p;
  q.position.x[7] += Real(1);
  write_snapshot(dir / "c.h5", q, info);
  EXPECT_NE(test::slurp(dir / "a.h5"), test::slurp(dir / "c.h5"));
}

TYPED_TEST(SnapshotTest, ASelectionOfRowsWritesTheSubsetsBytes) {
  using Real = TypeParam;
  TempDir dir;
  const auto p = test::make_particles<Real>(500);
  const std::vector<std::size_t> rows{3, 4, 17, 250, 499};
  write_snapshot(dir / "rows.h5", p, SnapshotInfo{}, std::span<const std::size_t>(rows));
  write_snapshot(dir / "subset.h5", p.subset(rows), SnapshotInfo{});
  EXPECT_EQ(test::slurp(dir / "rows.h5"), test::slurp(dir / "subset.h5"));
  EXPECT_EQ(read_snapshot(dir / "rows.h5").ids, (std::vector<std::uint64_t>{p.id[3], p.id[4], p.id[17], p.id[250], p.id[499]}));
  const std::vector<std::size_t> beyond{2, 500};
  EXPECT_THROW(write_snapshot(dir / "bad.h5", p, SnapshotInfo{}, std::span<const std::size_t>(beyond)), std::out_of_range);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.h5"));
}

TYPED_TEST(SnapshotTest, NoParticlesIsAValidSnapshot) {
  using Real = TypeParam;
  TempDir dir;
  write_snapshot(dir / "e.h5", ParticleSet<Real>(), SnapshotInfo{});
  const SnapshotFile s = read_snapshot(dir / "e.h5");
  EXPECT_EQ(s.count, 0u);
  EXPECT_TRUE(s.datasets.at("Coordinates").values.empty());
}

TEST(Snapshot, AFailedWriteKeepsTheOldFile) {
  TempDir dir;
  const auto p = test::make_particles<double>(10);
  write_snapshot(dir / "s.h5", p, SnapshotInfo{});
  const std::string before = test::slurp(dir / "s.h5");
  std::filesystem::create_directory(dir / "s.h5.dir");
  EXPECT_THROW(write_snapshot(dir / "s.h5.dir", p, SnapshotInfo{}), IoError);  // a directory in the way
  EXPECT_EQ(test::slurp(dir / "s.h5"), before);
}

// Runs tests/io/gadget_files.py (h5py: an independent writer) to make `kind` in dir.
void gadget_file(const std::filesystem::path& dir, const std::string& kind) {
  const std::string cmd = "/usr/bin/python3 " SWIRL_SOURCE_DIR "/tests/io/gadget_files.py " + kind + " " +
                          (dir / (kind + ".h5")).string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << " (needs Debian's python3-h5py: make deps)";
}

std::string error_of(const std::filesystem::path& file) {
  try {
    read_snapshot(file);
  } catch (const IoError& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(Snapshot, AFileWrittenByH5pyIsRead) {
  TempDir dir;
  // Gadget initial conditions: one mass in MassTable, no Masses, no Velocities, float32 coordinates.
  gadget_file(dir.path(), "ics");
  const SnapshotFile s = read_snapshot(dir / "ics.h5");
  EXPECT_EQ(s.version, 0);
  EXPECT_EQ(s.info.type, PartType::Collisionless);
  ASSERT_EQ(s.count, 5u);
  EXPECT_EQ(s.ids, (std::vector<std::uint64_t>{10, 11, 12, 13, 14}));
  EXPECT_EQ(s.datasets.at("Masses").values, std::vector<double>(5, 0.2));
  EXPECT_EQ(s.datasets.at("Velocities").values, std::vector<double>(15, 0.0));
  const auto& x = s.datasets.at("Coordinates").values;
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(x[3 * i + 1], double(float(0.1 * double(i))));
  EXPECT_EQ(s.info.time, 0.5);
}

// A file with several types is read one type at a time, any of Gadget's six
// when asked for; what the file says of its units is reported, not applied.
TEST(Snapshot, OneTypeAtATimeAndTheFilesUnitsAreReported) {
  TempDir dir;
  gadget_file(dir.path(), "gas_and_halo");  // 3 of type 0 with Masses, 5 of type 1 by MassTable
  EXPECT_EQ(snapshot_particle_counts(dir / "gas_and_halo.h5"), (std::array<std::uint64_t, 6>{3, 5, 0, 0, 0, 0}));
  const SnapshotFile gas = read_snapshot(dir / "gas_and_halo.h5", 0);
  EXPECT_EQ(gas.info.type, PartType::Gas);
  ASSERT_EQ(gas.count, 3u);
  EXPECT_EQ(gas.datasets.at("Masses").values, (std::vector<double>{0.3, 0.1, 0.7}));
  const SnapshotFile halo = read_snapshot(dir / "gas_and_halo.h5", 1);
  ASSERT_EQ(halo.count, 5u);
  EXPECT_EQ(halo.datasets.at("Masses").values, std::vector<double>(5, 0.2));
  EXPECT_NE(error_of(dir / "gas_and_halo.h5").find("has particles of types 0 and 1"), std::string::npos);
  try {
    read_snapshot(dir / "gas_and_halo.h5", 4);
    ADD_FAILURE() << "a missing group was read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/PartType4: missing (the file has /PartType0, /PartType1)"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(halo.unit_system.empty());
  EXPECT_FALSE(halo.cgs_units);

  gadget_file(dir.path(), "kpc_units");
  const SnapshotFile kpc = read_snapshot(dir / "kpc_units.h5");
  ASSERT_TRUE(kpc.cgs_units);
  EXPECT_EQ(kpc.cgs_units->length, 3.08567758e21);
  EXPECT_EQ(kpc.cgs_units->mass, 1.98841e43);
  EXPECT_EQ(kpc.cgs_units->time, 3.08567758e16);
  gadget_file(dir.path(), "nbody_units");
  EXPECT_EQ(read_snapshot(dir / "nbody_units.h5").unit_system, "nbody");

  // swirl's own SI frames say so both ways.
  write_snapshot(dir / "si.h5", test::make_particles<double>(2), SnapshotInfo{});
  const SnapshotFile si = read_snapshot(dir / "si.h5");
  EXPECT_EQ(si.unit_system, "si");
  ASSERT_TRUE(si.cgs_units);
  EXPECT_EQ(si.cgs_units->length, 100.0);
  EXPECT_EQ(si.cgs_units->mass, 1000.0);
  EXPECT_EQ(si.cgs_units->time, 1.0);
}

TEST(Snapshot, BadFilesAreRefusedNamingTheDataset) {
  TempDir dir;
  for (const auto& [kind, expected] : std::vector<std::pair<std::string, std::string>>{
           {"no_header", "/Header: missing"},
           {"no_coordinates", "/PartType1/Coordinates: missing"},
           {"flat_coordinates", "/PartType1/Coordinates: has 1 columns, expected 3"},
           {"short_masses", "/PartType1/Masses: has 4 rows, the header says 5 particles"},
           {"nan_velocity", "/PartType1/Velocities: the value of particle 3 (column 0) is not finite"},
           {"two_types", "has particles of types 0 and 1"},
           {"no_mass", "/PartType1/Masses: missing, and /Header/MassTable gives no mass"},
           {"string_coordinates", "/PartType1/Coordinates: is not numeric"},
           {"future", "/Header/SwirlFormatVersion: is 99, newer than this swirl's"},
           {"split", "/Header/NumFilesPerSnapshot: is 2: this file is one part of a snapshot split"},
       }) {
    SCOPED_TRACE(kind);
    gadget_file(dir.path(), kind);
    const std::string e = error_of(dir / (kind + ".h5"));
    EXPECT_NE(e.find(expected), std::string::npos) << e;
    EXPECT_NE(e.find(kind + ".h5"), std::string::npos) << e;
  }
  test::spit(dir / "text.h5", "not hdf5 at all");
  EXPECT_NE(error_of(dir / "text.h5").find("not an HDF5 file"), std::string::npos);
  EXPECT_NE(error_of(dir / "missing.h5").find("not a regular file"), std::string::npos);
}

}  // namespace
}  // namespace swirl::io
