// Loading valid scenes: values, defaults, files, the example, scene_hash.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

using test::edit;
using test::kFullScene;
using test::kMinimalScene;

TEST(LoadScene, FullSceneParsesIntoExpectedValues) {
  const Scene s = parse_scene(kFullScene, "full.toml");
  EXPECT_EQ(s.file, "full.toml");
  EXPECT_EQ(s.precision, Precision::Double);
  EXPECT_EQ(s.dt, 0.001);
  ASSERT_TRUE(s.end_time.has_value());
  EXPECT_EQ(*s.end_time, 0.5);
  EXPECT_FALSE(s.steps.has_value());
  EXPECT_EQ(s.block_size, 256u);
  EXPECT_EQ(s.box.lo, (Vec3d{0, 0, 0}));
  EXPECT_EQ(s.box.hi, (Vec3d{1, 1, 1}));
  EXPECT_EQ(s.restitution, 0.25);
  EXPECT_EQ(s.gravity, (Vec3d{0, -1, -9.81}));
  EXPECT_EQ(s.output_interval, 0.05);
  EXPECT_EQ(s.formats, (std::vector{OutputFormat::Csv, OutputFormat::Vtp}));
  ASSERT_EQ(s.sources.size(), 3u);

  const auto& lattice = std::get<LatticeSource>(s.sources[0]);
  EXPECT_EQ(lattice.region.lo, (Vec3d{0.1, 0.1, 0.1}));
  EXPECT_EQ(lattice.region.hi, (Vec3d{0.5, 0.5, 0.5}));
  EXPECT_EQ(lattice.spacing, 0.1);
  EXPECT_EQ(lattice.jitter, 0.2);
  EXPECT_EQ(lattice.seed, 7u);
  EXPECT_EQ(lattice.mass, 0.001);
  EXPECT_EQ(lattice.velocity, (Vec3d{1, 0, 0}));

  const auto& random = std::get<RandomSource>(s.sources[1]);
  EXPECT_EQ(random.region.lo, (Vec3d{0.6, 0.6, 0.6}));
  EXPECT_EQ(random.region.hi, (Vec3d{0.9, 0.9, 0.9}));
  EXPECT_EQ(random.count, 100u);
  EXPECT_EQ(random.seed, 3u);
  EXPECT_EQ(random.mass, 0.002);
  EXPECT_EQ(random.velocity, (Vec3d{0, 0, -1}));

  const auto& list = std::get<ListSource>(s.sources[2]);
  EXPECT_EQ(list.positions, (std::vector<Vec3d>{{0.5, 0.5, 0.9}, {0.25, 0.75, 0.5}}));
  EXPECT_EQ(list.velocities, (std::vector<Vec3d>{{0, 0, 1}, {1, 1, 1}}));
  EXPECT_EQ(list.masses, (std::vector{0.5, 1.5}));

  EXPECT_EQ(count_particles(s), 64u + 100u + 2u);
}

TEST(LoadScene, DefaultsApplyWhenKeysAreAbsent) {
  const Scene s = parse_scene(kMinimalScene, "minimal.toml");
  EXPECT_EQ(s.precision, Precision::Float);
  EXPECT_EQ(s.dt, 0.01);
  EXPECT_FALSE(s.end_time.has_value());
  ASSERT_TRUE(s.steps.has_value());
  EXPECT_EQ(*s.steps, 10u);
  EXPECT_EQ(s.block_size, 1024u);
  EXPECT_EQ(s.restitution, 0.5);
  EXPECT_EQ(s.gravity, (Vec3d{0, 0, -9.81}));
  EXPECT_EQ(s.output_interval, 0.0);
  EXPECT_EQ(s.formats, std::vector{OutputFormat::Vtp});
  ASSERT_EQ(s.sources.size(), 1u);
  const auto& list = std::get<ListSource>(s.sources[0]);
  EXPECT_TRUE(list.velocities.empty());
  EXPECT_EQ(list.masses, std::vector{1.0});
}

TEST(LoadScene, SourceDefaults) {
  const std::string text = kMinimalScene + R"(
[[particles]]
kind = "lattice"
min = [0, 0, 0]
max = [0.5, 0.5, 0.5]
spacing = 0.25
mass = 1

[[particles]]
kind = "random"
min = [0, 0, 0]
max = [0.5, 0.5, 0.5]
count = 3
mass = 1
)";
  const Scene s = parse_scene(text, "scene.toml");
  ASSERT_EQ(s.sources.size(), 3u);
  const auto& lattice = std::get<LatticeSource>(s.sources[1]);
  EXPECT_EQ(lattice.jitter, 0.0);
  EXPECT_EQ(lattice.seed, 1u);
  EXPECT_EQ(lattice.velocity, (Vec3d{0, 0, 0}));
  const auto& random = std::get<RandomSource>(s.sources[2]);
  EXPECT_EQ(random.seed, 1u);
  EXPECT_EQ(random.velocity, (Vec3d{0, 0, 0}));
}

TEST(LoadScene, IntegersAreAcceptedWhereNumbersAreExpected) {
  const Scene s = parse_scene(edit(edit(kMinimalScene, "dt = 0.01", "dt = 1"), "mass = 1", "mass = 2"), "s.toml");
  EXPECT_EQ(s.dt, 1.0);
  EXPECT_EQ(std::get<ListSource>(s.sources[0]).masses, std::vector{2.0});
}

TEST(LoadScene, SingleFormatStringAndBothFormats) {
  const std::string csv = kMinimalScene + "[output]\nformat = \"csv\"\n";
  EXPECT_EQ(parse_scene(csv, "s.toml").formats, std::vector{OutputFormat::Csv});
  const std::string both = kMinimalScene + "[output]\nformat = [\"vtp\", \"csv\"]\n";
  EXPECT_EQ(parse_scene(both, "s.toml").formats, (std::vector{OutputFormat::Vtp, OutputFormat::Csv}));
}

TEST(LoadScene, ListMassScalarAppliesToEveryPosition) {
  const std::string text = edit(kMinimalScene, "positions = [[0, 0, 0]]", "positions = [[0, 0, 0], [1, 1, 1], [-1, 0, 1]]");
  EXPECT_EQ(std::get<ListSource>(parse_scene(text, "s.toml").sources[0]).masses, (std::vector{1.0, 1.0, 1.0}));
}

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("swirl_scene_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
};

using LoadFile = TempDir;

TEST_F(LoadFile, ReadsTheFileAndNamesItInMessages) {
  const auto path = write("good.toml", kFullScene);
  const Scene s = load_scene(path);
  EXPECT_EQ(s.file, path.string());
  EXPECT_EQ(count_particles(s), 166u);

  const auto bad = write("bad.toml", edit(kFullScene, "dt = 0.001", "dt = 0"));
  try {
    (void)load_scene(bad);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), bad.string() + ": simulation.dt: must be > 0, got 0");
  }
}

TEST_F(LoadFile, AppliesOverrides) {
  const std::vector<std::string> overrides{"box.restitution=1"};
  EXPECT_EQ(load_scene(write("s.toml", kFullScene), overrides).restitution, 1.0);
}

TEST_F(LoadFile, MissingFileIsAnErrorNamingTheFileAndTheReason) {
  const auto path = dir_ / "nope.toml";
  try {
    (void)load_scene(path);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": cannot open: No such file or directory");
  }
}

TEST_F(LoadFile, DirectoryIsAnErrorNamingTheReason) {
  try {
    (void)load_scene(dir_);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), dir_.string() + ": is a directory; swirl reads only regular files");
  }
}

TEST_F(LoadFile, BadScenesWriteNoFiles) {
  const auto bad = write("bad.toml", edit(kFullScene, "restitution = 0.25", "restitution = 2"));
  const auto old_cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir_);
  auto listing = [&] {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir_)) names.push_back(e.path().string());
    return names;
  };
  const auto before = listing();
  EXPECT_THROW((void)load_scene(bad), SceneError);
  EXPECT_THROW((void)load_scene(write("syntax.toml", "[box\n")), SceneError);
  EXPECT_THROW((void)load_scene(dir_ / "missing.toml"), SceneError);
  std::filesystem::current_path(old_cwd);
  auto after = listing();
  std::erase(after, (dir_ / "syntax.toml").string());
  EXPECT_EQ(before, after);
}

// The DFSPH benchmark's scene (docs/performance/dfsph.md, tools/bench_dfsph.py)
// loads as the script runs it: both methods, both sizes, with the documented
// lattices (40 x 60 x 50 and 80 x 120 x 100 fluid particles) and h = 2 spacings.
TEST(DfsphBenchScene, LoadsAsTheBenchmarkRunsIt) {
  const auto file = std::filesystem::path(SWIRL_SOURCE_DIR) / "bench" / "dfsph" / "dam_break.toml";
  struct Size {
    std::string spacing, h;
    double s;
    std::array<double, 3> cells;
  };
  for (const Size& size : {Size{"0.008", "0.016", 0.008, {40, 60, 50}}, Size{"0.004", "0.008", 0.004, {80, 120, 100}}})
    for (const std::string method : {"dfsph", "wcsph"}) {
      SCOPED_TRACE(method + " at " + size.spacing);
      const std::vector<std::string> sets{"particles.0.spacing=" + size.spacing, "sph.smoothing_length=" + size.h,
                                          "sph.method=\"" + method + "\"", "output.format=\"csv\""};
      const Scene s = load_scene(file, sets);
      ASSERT_TRUE(s.sph.has_value());
      EXPECT_EQ(s.sph->method, method == "dfsph" ? sph::SphMethod::Dfsph : sph::SphMethod::Wcsph);
      EXPECT_EQ(s.sph->smoothing_length, 2 * size.s);
      EXPECT_TRUE(s.has_boundary_particles());
      ASSERT_EQ(s.sources.size(), 1u);
      const auto& block = std::get<LatticeSource>(s.sources[0]);
      EXPECT_EQ(block.spacing, size.s);
      for (int axis = 0; axis < 3; ++axis)
        EXPECT_NEAR((block.region.hi[axis] - block.region.lo[axis]) / size.s, size.cells[std::size_t(axis)], 1e-9);
    }
}

TEST(FallingBlockExample, LoadsAsTheDocumentedDemo) {
  const Scene s = load_scene(std::filesystem::path(SWIRL_SOURCE_DIR) / "examples" / "falling_block.toml");
  EXPECT_EQ(s.precision, Precision::Float);
  EXPECT_EQ(s.dt, 1e-3);
  ASSERT_TRUE(s.end_time.has_value());
  EXPECT_EQ(*s.end_time, 1.5);
  EXPECT_EQ(s.total_steps(), 1500u);
  EXPECT_EQ(s.restitution, 0.5);
  EXPECT_EQ(s.output_interval, 0.02);
  EXPECT_EQ(s.formats, std::vector{OutputFormat::Vtp});
  EXPECT_EQ(s.box.lo, (Vec3d{0, 0, 0}));
  EXPECT_EQ(s.box.hi, (Vec3d{1, 1, 1}));
  EXPECT_LT(s.gravity.z, 0);
  ASSERT_EQ(s.sources.size(), 1u);
  const auto& block = std::get<LatticeSource>(s.sources[0]);
  EXPECT_GT(block.jitter, 0);
  EXPECT_LE(block.jitter, 0.2);
  EXPECT_GE(block.region.lo.z, 0.5) << "the block starts in the upper part of the box";
  EXPECT_EQ(count_particles(s), 8000u);
}

// A scene's hash depends on its values, not on how the file spells them.
TEST(SceneHash, IsStableAndIgnoresFormattingAndFileName) {
  const Scene a = parse_scene(kFullScene, "a.toml");
  std::string respelt = edit(kFullScene, "# a full scene", "# the same scene, respelt");
  respelt = edit(respelt, "dt = 0.001", "dt = 1e-3");
  respelt = edit(respelt, "max = [1, 1, 1]\nrestitution = 0.25", "restitution = 0.25   # reordered\nmax = [1.0, 1.0, 1.0]");
  const Scene b = parse_scene(respelt, "elsewhere/b.toml");
  EXPECT_EQ(scene_hash(a), scene_hash(b));
  EXPECT_EQ(scene_hash(a), scene_hash(parse_scene(kFullScene, "a.toml")));
  // Checkpoints store the hash, so it must not drift between versions or
  // machines. The value is FNV-1a 64 of the canonical text, computed
  // independently of swirl (with Python's '%.17g'): one line per declared key,
  //   simulation.precision = "float"\nsimulation.units = "si"\nsimulation.dt = 0.01\n
  //   simulation.steps = 10\nsimulation.block_size = 1024\nsimulation.cfl = 0.59999999999999998\n
  //   ... forces.gravity = [0, 0, -9.8100000000000005]\nforces.damping = 0\n ...
  //   [[particles]]\nkind = "list"\npositions = [[0, 0, 0]]\nvelocities = []\nmasses = [1]\n
  // (docs/scenes.md, "Scene hash"). It changed with the key declarations of
  // scene/keys.hpp (was 0x2b70d7fecceb7244).
  EXPECT_EQ(scene_hash(parse_scene(kMinimalScene, "m.toml")), 0xc839140e3db0a054u);
}

TEST(SceneHash, ChangesWithAnyValue) {
  const auto base = scene_hash(parse_scene(kFullScene, "s.toml"));
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"dt = 0.001", "dt = 0.0010000000000000002"},
           {"precision = \"double\"", "precision = \"float\""},
           {"end_time = 0.5", "steps = 500"},
           {"block_size = 256", "block_size = 255"},
           {"restitution = 0.25", "restitution = 0.26"},
           {"gravity = [0, -1, -9.81]", "gravity = [0, -1, -9.8]"},
           {"interval = 0.05", "interval = 0"},
           {"format = [\"csv\", \"vtp\"]", "format = [\"vtp\", \"csv\"]"},
           {"seed = 7", "seed = 8"},
           {"jitter = 0.2", "jitter = 0.3"},
           {"count = 100", "count = 101"},
           {"masses = [0.5, 1.5]", "masses = [0.5, 1.25]"},
           {"velocities = [[0, 0, 1], [1, 1, 1]]", "velocities = [[0, 0, 1], [1, 1, 0]]"},
       }) {
    EXPECT_NE(scene_hash(parse_scene(edit(kFullScene, from, to), "s.toml")), base) << from << " -> " << to;
  }
}

}  // namespace
}  // namespace swirl::scene
