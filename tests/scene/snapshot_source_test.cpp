// [[particles]] kind = "snapshot": a scene starting from a Gadget-format HDF5
// file. A file swirl wrote gives its particles back bit for bit, files written
// by h5py (tests/io/gadget_files.py, an independent writer) load with masses
// per particle or from MassTable, the path is resolved against the scene's
// folder and written back absolute, and every refusal names the file, the
// group or dataset and the reason.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/io_test_util.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/keys.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/scene/validate.hpp"

namespace swirl::scene {
namespace {

namespace fs = std::filesystem;
using io::test::TempDir;

// `kind` of tests/io/gadget_files.py written by h5py to `path`.
void h5py_file(const fs::path& path, const std::string& kind) {
  fs::create_directories(path.parent_path());
  const std::string cmd =
      "/usr/bin/python3 " SWIRL_SOURCE_DIR "/tests/io/gadget_files.py " + kind + " '" + path.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << " (needs Debian's python3-h5py: make deps)";
}

// An open-space N-body scene of one snapshot source with `keys`.
std::string nbody_scene(const std::string& keys, const std::string& units = "nbody") {
  return fmt::format(R"([simulation]
units = "{}"
precision = "double"
dt = 0.01
steps = 1
[nbody]
softening = 0.01
[[particles]]
kind = "snapshot"
{}
)",
                     units, keys);
}

void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  io::test::spit(path, text);
}

std::string error_of(const fs::path& scene_file) {
  try {
    (void)load_scene(scene_file);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<no error>";
}

// Particles whose values need every bit: thirds, a −0, a subnormal, extremes.
template <class Real>
ParticleSet<Real> awkward_particles(std::size_t n) {
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Real r = Real(double(i) + 1) / Real(3);
    p.position.set(i, {r, -r * Real(7), Real(1) / (r + Real(0.1))});
    p.velocity.set(i, {Real(0.5) - r, r * r, Real(-0.0)});
    p.mass[i] = Real(1) / (Real(11) + r);
  }
  p.position.x[0] = Real(-0.0);
  p.position.y[1] = std::numeric_limits<Real>::denorm_min();
  p.velocity.z[2] = std::numeric_limits<Real>::max();
  return p;
}

template <class Real>
class SnapshotSourceRoundTrip : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SnapshotSourceRoundTrip, Precisions);

// What a run writes (io::write_snapshot in the run's precision) comes back bit
// for bit through a scene of the same precision.
TYPED_TEST(SnapshotSourceRoundTrip, AFrameGivesItsParticlesBackBitForBit) {
  using Real = TypeParam;
  TempDir dir;
  const auto written = awkward_particles<Real>(40);
  io::SnapshotInfo info;
  info.type = io::PartType::Collisionless;
  info.si_units = false;
  info.gravitational_constant = 1;
  io::write_snapshot(dir / "frame.h5", written, info);
  write_text(dir / "s.toml", nbody_scene("file = \"frame.h5\"") + "\n");
  const Scene s = load_scene(dir / "s.toml", std::vector<std::string>{
      fmt::format("simulation.precision=\"{}\"", sizeof(Real) == 4 ? "float" : "double")});
  ASSERT_EQ(count_particles(s), written.size());
  const auto got = make_particles<Real>(s);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(io::test::bytes_of(std::vector<Real>(got.position[axis].begin(), got.position[axis].end())),
              io::test::bytes_of(std::vector<Real>(written.position[axis].begin(), written.position[axis].end())));
    EXPECT_EQ(io::test::bytes_of(std::vector<Real>(got.velocity[axis].begin(), got.velocity[axis].end())),
              io::test::bytes_of(std::vector<Real>(written.velocity[axis].begin(), written.velocity[axis].end())));
  }
  EXPECT_EQ(io::test::bytes_of(std::vector<Real>(got.mass.begin(), got.mass.end())),
            io::test::bytes_of(std::vector<Real>(written.mass.begin(), written.mass.end())));
  for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got.id[i], i) << "ids in file order, like every source";
}

TEST(SnapshotSource, AnH5pyFileWithMassTableOnlyLoadsMovedAndKicked) {
  TempDir dir;
  h5py_file(dir / "ics" / "ics.h5", "ics");  // 5 type-1 particles, MassTable 0.2, float32, no Velocities
  write_text(dir / "scenes" / "s.toml",
             nbody_scene("file = \"../ics/ics.h5\"\noffset = [1, 0, 0.5]\nvelocity = [0, 0, 2]"));
  const Scene s = load_scene(dir / "scenes" / "s.toml");
  const auto& src = std::get<SnapshotSource>(s.sources.at(0));
  EXPECT_EQ(src.file, (dir / "ics" / "ics.h5").lexically_normal().string()) << "absolute, against the scene's folder";
  EXPECT_FALSE(src.part_type) << "the default stays the default; the content says which group was read";
  EXPECT_EQ(src.content->group, "/PartType1");
  const auto p = make_particles<double>(s);
  ASSERT_EQ(p.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(p.position.get(i), (Vec3d{1, double(float(0.1 * double(i))), 0.5})) << i;
    EXPECT_EQ(p.velocity.get(i), (Vec3d{0, 0, 2})) << i;
    EXPECT_EQ(p.mass[i], 0.2) << i;
  }
}

TEST(SnapshotSource, PerParticleMassesAndOneSourcePerType) {
  TempDir dir;
  h5py_file(dir / "gh.h5", "gas_and_halo");  // /PartType0: 3 with Masses and Velocities; /PartType1: 5
  write_text(dir / "s.toml", nbody_scene("file = \"gh.h5\"\npart_type = 0\n[[particles]]\nkind = \"snapshot\"\n"
                                         "file = \"gh.h5\"\npart_type = 1"));
  const auto p = make_particles<double>(load_scene(dir / "s.toml"));
  ASSERT_EQ(p.size(), 8u);
  const std::vector<Vec3d> x{{0.5, -0.25, 1.0 / 3.0}, {-0.0, 2.0, 1e-300}, {-1.5, 0.125, 7.0}};
  const std::vector<Vec3d> v{{1, 2, 3}, {-0.0, 0.1, -0.2}, {4, 5, 6}};
  const std::vector<double> m{0.3, 0.1, 0.7};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(p.position.get(i), x[i]);
    EXPECT_EQ(p.velocity.get(i), v[i]);
    EXPECT_EQ(p.mass[i], m[i]);
  }
  EXPECT_TRUE(std::signbit(p.position.x[1])) << "−0 kept: a zero offset adds nothing";
  EXPECT_TRUE(std::signbit(p.velocity.x[1]));
  for (std::size_t i = 3; i < 8; ++i) EXPECT_EQ(p.mass[i], 0.2) << "MassTable of type 1";
}

// The path is resolved once, against the scene file's folder, and the saved
// TOML holds it absolute: the copy a run folder keeps loads from anywhere, to
// the same file and the same hash (what `swirl run --resume` relies on).
TEST(SnapshotSource, TheSavedSceneNamesTheFileAbsolutelyAndHashesAlike) {
  TempDir dir;
  // A folder name TOML must escape.
  const fs::path odd = dir / "we\"ird\\ dir";
  h5py_file(odd / "ics.h5", "ics");
  write_text(odd / "s.toml", nbody_scene("file = './sub/../ics.h5'"));
  const Scene first = load_scene(odd / "s.toml");
  const std::string absolute = (odd / "ics.h5").string();
  EXPECT_EQ(std::get<SnapshotSource>(first.sources[0]).file, absolute);
  const Scene saved = parse_scene(first.toml, (dir / "elsewhere" / "run" / "scene.toml").string());
  EXPECT_EQ(std::get<SnapshotSource>(saved.sources[0]).file, absolute);
  EXPECT_EQ(scene_hash(saved), scene_hash(first));
  EXPECT_EQ(saved.toml, first.toml);
  // The canonical text writes the path as a TOML basic string.
  EXPECT_EQ(value_text(KeyValue{std::string_view("a\"b\\c\nd\x01")}, false), "\"a\\\"b\\\\c\\nd\\u0001\"");
  EXPECT_EQ(std::get<SnapshotSource>(parse_scene(nbody_scene("file = " + value_text(KeyValue{std::string_view(absolute)}, true)),
                                                 "<dict>")
                                         .sources[0])
                .file,
            absolute);
}

struct ErrorCase {
  std::string name;
  std::string file_kind;  // gadget_files.py kind written to f.h5 ("" for none)
  std::string keys;       // the source's keys
  std::string units;
  std::string expected;   // after "<scene>: particles[0]."; <f> stands for the file's absolute path
};

TEST(SnapshotSource, EachRefusalNamesTheFileTheGroupOrDatasetAndTheReason) {
  TempDir dir;
  const std::string f = (dir / "f.h5").string();
  const auto expand = [&](std::string text) {
    for (auto at = text.find("<f>"); at != std::string::npos; at = text.find("<f>")) text.replace(at, 3, f);
    return text;
  };
  const std::vector<ErrorCase> cases{
      {"missing file", "", "file = \"f.h5\"", "nbody",
       "file: <f>: no such file (the scene reads it whenever it is loaded, `swirl run --resume` included, which "
       "rebuilds the scene before the checkpoint replaces its particles: put the file back at this path)"},
      {"missing group", "ics", "file = \"f.h5\"\npart_type = 3", "nbody",
       "file: <f>: /PartType3: missing (the file has /PartType1)"},
      {"two types, none chosen", "gas_and_halo", "file = \"f.h5\"", "nbody",
       "part_type: missing, and <f> has particles in /PartType0 (3), /PartType1 (5): give part_type = 0 or 1 (one "
       "[[particles]] source per type)"},
      {"NaN", "nan_velocity", "file = \"f.h5\"", "nbody",
       "file: <f>: /PartType1/Velocities: the value of particle 3 (column 0) is not finite"},
      {"wrong shape", "flat_coordinates", "file = \"f.h5\"", "nbody",
       "file: <f>: /PartType1/Coordinates: has 1 columns, expected 3"},
      {"no mass", "no_mass", "file = \"f.h5\"", "nbody",
       "file: <f>: /PartType1/Masses: missing, and /Header/MassTable gives no mass for type 1"},
      {"UnitSystem", "nbody_units", "file = \"f.h5\"", "si",
       "file: <f>: /Header/UnitSystem is \"nbody\", but the scene's simulation.units is \"si\": its numbers would be "
       "taken in the wrong units"},
      {"/Units in an SI scene", "kpc_units", "file = \"f.h5\"", "si",
       "file: <f>: /Units gives U_L = 3.08567758e+21 cm, U_M = 1.98841e+43 g, U_t = 3.08567758e+16 s, not SI's m, kg "
       "and s (100, 1000, 1): swirl does not convert units; convert the file's numbers to SI"},
      {"/Units in an N-body scene", "kpc_units", "file = \"f.h5\"", "nbody",
       "file: <f>: /Units gives U_L = 3.08567758e+21 cm, U_M = 1.98841e+43 g, U_t = 3.08567758e+16 s, physical "
       "units, but the scene's simulation.units is \"nbody\" (G = 1): swirl does not convert units; use "
       "simulation.units = \"si\" with a file in m, kg and s"},
      {"empty path", "", "file = \"\"", "nbody", "file: must not be empty"},
      {"not a string", "", "file = 3", "nbody", "file: expected a string, got an integer"},
      {"not HDF5", "", "file = \"s.toml\"", "nbody", "file: " + (dir / "s.toml").string() + ": not an HDF5 file"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    fs::remove(f);
    if (!c.file_kind.empty()) h5py_file(f, c.file_kind);
    write_text(dir / "s.toml", nbody_scene(c.keys, c.units));
    const std::string e = error_of(dir / "s.toml");
    EXPECT_EQ(e, expand((dir / "s.toml").string() + ": particles[0]." + c.expected));
  }
}

TEST(SnapshotSource, AParticleOutsideTheBoxOrAnEmptyGroupIsRefused) {
  TempDir dir;
  h5py_file(dir / "ics.h5", "ics");  // x = 0, y = 0.1·i, z = 0
  const std::string boxed = R"([simulation]
dt = 0.01
steps = 1
[box]
min = [-1, -1, -1]
max = [1, 0.35, 1]
[[particles]]
kind = "snapshot"
file = "ics.h5"
)";
  write_text(dir / "s.toml", boxed);
  EXPECT_EQ(error_of(dir / "s.toml"),
            fmt::format("{}: particles[0].file: {}: /PartType1/Coordinates: particle 4 at (0, {}, 0) lies outside the "
                        "box [(-1, -1, -1), (1, 0.35, 1)]",
                        (dir / "s.toml").string(), (dir / "ics.h5").string(), double(float(0.4))));
  write_text(dir / "s.toml", boxed + "offset = [0, -0.1, 0]\n");
  EXPECT_EQ(error_of(dir / "s.toml"), "<no error>") << "the offset moves the particles into the box";

  io::SnapshotInfo info;
  info.type = io::PartType::Gas;
  io::write_snapshot(dir / "empty.h5", ParticleSet<double>(0), info);
  write_text(dir / "s.toml", nbody_scene("file = \"empty.h5\"", "si"));
  EXPECT_EQ(error_of(dir / "s.toml"), fmt::format("{}: particles[0].file: {}: /PartType0 holds no particles",
                                                  (dir / "s.toml").string(), (dir / "empty.h5").string()));
}

// swirl's own SI frame says "si" (UnitSystem) and m, kg, s (/Units): accepted
// by an SI scene, refused by an N-body one.
TEST(SnapshotSource, SwirlsOwnUnitsAreCheckedAgainstTheScenes) {
  TempDir dir;
  io::SnapshotInfo info;
  info.type = io::PartType::Collisionless;
  info.si_units = true;
  io::write_snapshot(dir / "si.h5", awkward_particles<double>(3), info);
  write_text(dir / "s.toml", nbody_scene("file = \"si.h5\"", "si"));
  EXPECT_EQ(error_of(dir / "s.toml"), "<no error>");
  write_text(dir / "s.toml", nbody_scene("file = \"si.h5\"", "nbody"));
  EXPECT_EQ(error_of(dir / "s.toml"),
            fmt::format("{}: particles[0].file: {}: /Header/UnitSystem is \"si\", but the scene's simulation.units is "
                        "\"nbody\": its numbers would be taken in the wrong units",
                        (dir / "s.toml").string(), (dir / "si.h5").string()));
}

// A Scene built in code has no content until someone reads the file.
TEST(SnapshotSource, ASourceBuiltInCodeWithoutContentIsRefused) {
  Scene s;
  s.walls = false;
  s.dt = 0.01;
  s.steps = 1;
  s.file = "code";
  SnapshotSource src;
  src.file = "/nowhere/ics.h5";
  s.sources.emplace_back(src);
  EXPECT_THROW(validate(s), SceneError);
  EXPECT_THROW((void)make_particles<double>(s), SceneError);
}

}  // namespace
}  // namespace swirl::scene
