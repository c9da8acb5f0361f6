// Invalid scenes: every class of error names the file, the key and the reason,
// in one line, and no input crashes the loader.
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <string>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

using test::edit;
using test::error_of;
using test::kFullScene;
using test::kMinimalScene;

struct Case {
  std::string name;
  std::string text;
  std::string expected;  // the whole message, after "scene.toml: "
};

// "scene.toml: <key>: <reason>" exactly, so file, key and reason are all checked.
void expect_error(const Case& c) {
  const std::string message = error_of(c.text);
  EXPECT_EQ(message, "scene.toml: " + c.expected) << c.name;
  EXPECT_EQ(message.find('\n'), std::string::npos) << c.name;
}

std::string full(std::string_view from, std::string_view to) { return edit(kFullScene, from, to); }
std::string minimal(std::string_view from, std::string_view to) { return edit(kMinimalScene, from, to); }
std::string without_particles() {
  return minimal("[[particles]]\nkind = \"list\"\npositions = [[0, 0, 0]]\nmass = 1\n", "");
}

TEST(SceneErrors, Numbers) {
  for (const Case& c : std::vector<Case>{
           {"negative dt", full("dt = 0.001", "dt = -0.001"), "simulation.dt: must be > 0, got -0.001"},
           {"zero dt", full("dt = 0.001", "dt = 0"), "simulation.dt: must be > 0, got 0"},
           {"nan dt", full("dt = 0.001", "dt = nan"), "simulation.dt: must be finite, got nan"},
           {"inf dt", full("dt = 0.001", "dt = +inf"), "simulation.dt: must be finite, got inf"},
           {"zero end_time", full("end_time = 0.5", "end_time = 0"), "simulation.end_time: must be > 0, got 0"},
           {"too many steps", full("end_time = 0.5", "end_time = 1e300"),
            "simulation.end_time: needs 1e+303 steps of dt = 0.001, more than the limit of 2^53"},
           {"zero steps", minimal("steps = 10", "steps = 0"), "simulation.steps: must be >= 1, got 0"},
           {"zero block_size", full("block_size = 256", "block_size = 0"), "simulation.block_size: must be >= 1, got 0"},
           {"restitution above 1", full("restitution = 0.25", "restitution = 1.5"),
            "box.restitution: must be in [0, 1], got 1.5"},
           {"negative restitution", full("restitution = 0.25", "restitution = -0.1"),
            "box.restitution: must be in [0, 1], got -0.1"},
           {"negative interval", full("interval = 0.05", "interval = -1"), "output.interval: must be >= 0, got -1"},
           {"nan interval", full("interval = 0.05", "interval = nan"), "output.interval: must be finite, got nan"},
           {"infinite gravity", full("gravity = [0, -1, -9.81]", "gravity = [0, -1, -inf]"),
            "forces.gravity[2]: must be finite, got -inf"},
           {"nan in box", full("min = [0, 0, 0]", "min = [0, 0, nan]"), "box.min[2]: must be finite, got nan"},
           {"nan in velocity", full("velocity = [1, 0, 0]", "velocity = [nan, 0, 0]"),
            "particles[0].velocity[0]: must be finite, got nan"},
           {"zero spacing", full("spacing = 0.1", "spacing = 0"), "particles[0].spacing: must be > 0, got 0"},
           {"jitter at 0.5", full("jitter = 0.2", "jitter = 0.5"), "particles[0].jitter: must be in [0, 0.5), got 0.5"},
           {"negative seed", full("seed = 7", "seed = -1"), "particles[0].seed: must be >= 0, got -1"},
           {"zero mass", full("mass = 0.001", "mass = 0"), "particles[0].mass: must be > 0, got 0"},
           {"zero count", full("count = 100", "count = 0"), "particles[1].count: must be in [1, 2147483648], got 0"},
           {"negative list mass", full("masses = [0.5, 1.5]", "masses = [0.5, -1.5]"),
            "particles[2].masses[1]: must be > 0, got -1.5"},
           {"infinite list mass", minimal("mass = 1", "mass = inf"), "particles[0].mass: must be finite, got inf"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, Types) {
  for (const Case& c : std::vector<Case>{
           {"string dt", full("dt = 0.001", "dt = \"0.001\""), "simulation.dt: expected a number, got a string"},
           {"boolean restitution", full("restitution = 0.25", "restitution = true"),
            "box.restitution: expected a number, got a boolean"},
           {"float steps", minimal("steps = 10", "steps = 10.0"), "simulation.steps: expected an integer, got a float"},
           {"float count", full("count = 100", "count = 1e2"), "particles[1].count: expected an integer, got a float"},
           {"kind as integer", full("kind = \"random\"", "kind = 1"), "particles[1].kind: expected a string, got an integer"},
           {"precision as integer", full("precision = \"double\"", "precision = 2"),
            "simulation.precision: expected a string, got an integer"},
           {"section as value", "simulation = 3\n", "simulation: expected a table, got an integer"},
           {"particles as table", edit(kMinimalScene, "[[particles]]", "[particles]"),
            "particles: expected an array of tables ([[particles]]), got a table"},
           {"particles of numbers", "particles = [1]\n" + without_particles(),
            "particles[0]: expected a table, got an integer"},
           {"format as number", full("format = [\"csv\", \"vtp\"]", "format = 1"),
            "output.format: expected a string or an array of strings, got an integer"},
           {"positions as table", minimal("positions = [[0, 0, 0]]", "positions = { x = 0 }"),
            "particles[0].positions: expected an array of [x, y, z] positions, got a table"},
           {"date as number", full("interval = 0.05", "interval = 1979-05-27"), "output.interval: expected a number, got a date"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, VectorsMustBeThreeNumbers) {
  for (const Case& c : std::vector<Case>{
           {"two numbers", full("min = [0, 0, 0]", "min = [0, 0]"), "box.min: expected an array of 3 numbers, got 2 elements"},
           {"four numbers", full("gravity = [0, -1, -9.81]", "gravity = [0, 0, 0, 0]"),
            "forces.gravity: expected an array of 3 numbers, got 4 elements"},
           {"scalar", full("min = [0, 0, 0]", "min = 0"), "box.min: expected an array of 3 numbers, got an integer"},
           {"string element", full("min = [0, 0, 0]", "min = [0, \"0\", 0]"), "box.min[1]: expected a number, got a string"},
           {"nested", full("velocity = [1, 0, 0]", "velocity = [[1], 0, 0]"),
            "particles[0].velocity[0]: expected a number, got an array"},
           {"list position", full("positions = [[0.5, 0.5, 0.9], [0.25, 0.75, 0.5]]", "positions = [[0.5, 0.5, 0.9], [0.25, 0.75]]"),
            "particles[2].positions[1]: expected an array of 3 numbers, got 2 elements"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, MissingRequiredKeys) {
  for (const Case& c : std::vector<Case>{
           {"dt", full("dt = 0.001\n", ""), "simulation.dt: missing required key"},
           {"simulation section", edit(kMinimalScene, "[simulation]\ndt = 0.01\nsteps = 10\n", ""),
            "simulation.dt: missing required key"},
           {"neither end_time nor steps", full("end_time = 0.5\n", ""),
            "simulation.end_time: missing required key (give end_time or simulation.steps)"},
           {"box.min", full("min = [0, 0, 0]\n", ""), "box.min: missing required key"},
           {"kind", full("kind = \"random\"\n", ""), "particles[1].kind: missing required key"},
           {"spacing", full("spacing = 0.1\n", ""), "particles[0].spacing: missing required key"},
           {"region", full("min = [0.6, 0.6, 0.6]\n", ""), "particles[1].min: missing required key"},
           {"count", full("count = 100\n", ""), "particles[1].count: missing required key"},
           {"lattice mass", full("mass = 0.001\n", ""), "particles[0].mass: missing required key"},
           {"positions", minimal("positions = [[0, 0, 0]]\n", ""), "particles[0].positions: missing required key"},
           {"list mass", minimal("mass = 1\n", ""),
            "particles[0].mass: missing required key (give mass, or particles[0].masses with one per position)"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, ConflictsAndLengths) {
  for (const Case& c : std::vector<Case>{
           {"end_time and steps", full("end_time = 0.5", "end_time = 0.5\nsteps = 3"),
            "simulation.steps: cannot be given together with simulation.end_time; give one of them"},
           {"mass and masses", full("masses = [0.5, 1.5]", "masses = [0.5, 1.5]\nmass = 1"),
            "particles[2].masses: cannot be given together with particles[2].mass; give one of them"},
           {"masses length", full("masses = [0.5, 1.5]", "masses = [0.5]"),
            "particles[2].masses: has 1 entries but particles[2].positions has 2"},
           {"velocities length", full("velocities = [[0, 0, 1], [1, 1, 1]]", "velocities = [[0, 0, 1], [1, 1, 1], [0, 0, 0]]"),
            "particles[2].velocities: has 3 entries but particles[2].positions has 2"},
           {"no positions", minimal("positions = [[0, 0, 0]]", "positions = []"),
            "particles[0].positions: must list at least one position"},
           {"duplicate format", full("format = [\"csv\", \"vtp\"]", "format = [\"vtp\", \"vtp\"]"),
            "output.format[1]: 'vtp' is listed twice"},
           {"no format", full("format = [\"csv\", \"vtp\"]", "format = []"), "output.format: must name at least one format"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, UnknownNamesListTheAllowedOnes) {
  for (const Case& c : std::vector<Case>{
           {"kind", full("kind = \"random\"", "kind = \"grid\""),
            "particles[1].kind: unknown kind 'grid' (allowed: 'lattice', 'random', 'list', 'fluid_block', 'fluid_sphere', 'fluid_mesh', 'plummer', 'uniform_sphere', 'uniform_cube', 'cold_collapse', 'plummer_collision', 'hernquist', 'nfw', 'king', 'disk_galaxy', 'snapshot', 'obstacle_box', 'obstacle_sphere', 'obstacle_cylinder', 'obstacle_plane', 'obstacle_mesh')"},
           {"precision", full("precision = \"double\"", "precision = \"single\""),
            "simulation.precision: unknown precision 'single' (allowed: 'float', 'double')"},
           {"format", full("format = [\"csv\", \"vtp\"]", "format = \"xml\""),
            "output.format: unknown format 'xml' (allowed: 'vtp', 'csv', 'hdf5')"},
           {"format in array", full("format = [\"csv\", \"vtp\"]", "format = [\"csv\", \"VTP\"]"),
            "output.format[1]: unknown format 'VTP' (allowed: 'vtp', 'csv', 'hdf5')"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, UnknownKeysSuggestTheClosestKnownKey) {
  for (const Case& c : std::vector<Case>{
           {"transposition", full("restitution = 0.25", "restitutoin = 0.25"),
            "box.restitutoin: unknown key (did you mean 'restitution'?)"},
           {"missing letter", full("spacing = 0.1", "spacng = 0.1"),
            "particles[0].spacng: unknown key (did you mean 'spacing'?)"},
           {"misspelt kind", full("kind = \"random\"", "knid = \"random\""),
            "particles[1].knid: unknown key (did you mean 'kind'?)"},
           {"dash", full("end_time = 0.5", "end-time = 0.5"), "simulation.end-time: unknown key (did you mean 'end_time'?)"},
           {"plural", full("velocity = [1, 0, 0]", "velocities = [1, 0, 0]"),
            "particles[0].velocities: unknown key for kind 'lattice' (did you mean 'velocity'?)"},
           {"section", edit(kMinimalScene, "[simulation]", "[simulaton]"),
            "simulaton: unknown section (did you mean 'simulation'?)"},
           {"nothing close", full("restitution = 0.25", "colour = \"red\""), "box.colour: unknown key"},
           {"unknown section", kMinimalScene + "[solver]\nname = \"sph\"\n", "solver: unknown section"},
           {"top-level key", "dt = 0.1\n" + kMinimalScene, "dt: unknown section"},
           {"key of another kind", full("spacing = 0.1", "spacing = 0.1\ncount = 3"),
            "particles[0].count: unknown key for kind 'lattice'"},
           {"subtable", kMinimalScene + "[box.sides]\nleft = 1\n", "box.sides: unknown key"},
           {"first in the file", full("restitution = 0.25", "restitution = 0.25\nzeta = 1\nalpha = 2"), "box.zeta: unknown key"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, ParticlesMustLieInsideTheBox) {
  for (const Case& c : std::vector<Case>{
           {"lattice region", full("max = [0.5, 0.5, 0.5]", "max = [0.5, 0.5, 1.5]"),
            "particles[0].max: (0.5, 0.5, 1.5) lies outside the box [(0, 0, 0), (1, 1, 1)]"},
           {"random region", full("min = [0.6, 0.6, 0.6]", "min = [-0.1, 0.6, 0.6]"),
            "particles[1].min: (-0.1, 0.6, 0.6) lies outside the box [(0, 0, 0), (1, 1, 1)]"},
           {"list position", full("positions = [[0.5, 0.5, 0.9], [0.25, 0.75, 0.5]]",
                                  "positions = [[0.5, 0.5, 0.9], [0.25, 0.75, 0.5], [0, 0, 0], [2, 0.5, 0.5]]"),
            "particles[2].positions[3]: (2, 0.5, 0.5) lies outside the box [(0, 0, 0), (1, 1, 1)]"},
       }) {
    expect_error(c);
  }
  // On the faces is inside.
  EXPECT_EQ(error_of(full("positions = [[0.5, 0.5, 0.9], [0.25, 0.75, 0.5]]", "positions = [[0, 0, 0], [1, 1, 1]]")),
            "<no error>");
}

TEST(SceneErrors, BoxesMustHavePositiveExtent) {
  for (const Case& c : std::vector<Case>{
           {"box", full("max = [1, 1, 1]", "max = [1, 0, 1]"),
            "box.max: must be greater than box.min on every axis, but along y 0 <= 0"},
           {"region", full("max = [0.9, 0.9, 0.9]", "max = [0.9, 0.9, 0.5]"),
            "particles[1].max: must be greater than particles[1].min on every axis, but along z 0.5 <= 0.6"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, NoParticles) {
  for (const Case& c : std::vector<Case>{
           {"lattice smaller than spacing", full("spacing = 0.1", "spacing = 0.5"),
            "particles[0]: makes no particles: the region is 0.4 long along x, less than the spacing 0.5"},
           {"no sources", without_particles(),
            "particles: no particles: the scene needs at least one [[particles]] source"},
           {"empty array", "particles = []\n" + without_particles(),
            "particles: no particles: the scene needs at least one [[particles]] source"},
       }) {
    expect_error(c);
  }
}

TEST(SceneErrors, TooManyParticlesAreRefusedBeforeAnythingIsMade) {
  const auto start = std::chrono::steady_clock::now();
  for (const Case& c : std::vector<Case>{
           {"tiny spacing", full("spacing = 0.1", "spacing = 1e-300"),
            "particles[0]: makes over 1.8e19 particles, more than the limit of 2147483648 (2^31); is the spacing too small?"},
           {"denormal spacing", full("spacing = 0.1", "spacing = 5e-324"),
            "particles[0]: makes over 1.8e19 particles, more than the limit of 2147483648 (2^31); is the spacing too small?"},
           {"small spacing", full("spacing = 0.1", "spacing = 0.0001"),
            "particles[0]: makes 64000000000 particles, more than the limit of 2147483648 (2^31); is the spacing too small?"},
           {"huge count", full("count = 100", "count = 9223372036854775807"),
            "particles[1].count: must be in [1, 2147483648], got 9223372036854775807"},
           {"total", full("count = 100", "count = 2147483648"),
            "particles: the sources make 2147483714 particles in total, more than the limit of 2147483648 (2^31)"},
       }) {
    expect_error(c);
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(SceneErrors, SyntaxErrorsGiveLineAndColumn) {
  const std::string text = edit(kFullScene, "block_size = 256", "block_size = = 256");
  const std::string message = error_of(text);
  EXPECT_EQ(message.rfind("scene.toml:6:14: ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;

  const std::string unterminated = error_of("[simulation]\ndt = 0.1\n[box\n");
  EXPECT_EQ(unterminated.rfind("scene.toml:3:", 0), 0u) << unterminated;

  const std::string duplicate = error_of("[simulation]\ndt = 0.1\ndt = 0.2\n");
  EXPECT_EQ(duplicate.rfind("scene.toml:3:", 0), 0u) << duplicate;
  EXPECT_NE(duplicate.find("dt"), std::string::npos) << duplicate;
}

TEST(SceneErrors, MessagesStayOnOneLine) {
  const std::string message = error_of(kMinimalScene + "[box.\"a\\nb\"]\n");
  EXPECT_EQ(message, "scene.toml: box.a\\x0ab: unknown key");
  try {
    (void)parse_scene(edit(kMinimalScene, "dt = 0.01", "dt = 0"), "two\nlines.toml");
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "two\\x0alines.toml: simulation.dt: must be > 0, got 0");
  }
}

// Whatever the bytes, the loader either returns a scene or throws SceneError.
TEST(SceneErrors, NoCrashOnAnyInput) {
  auto survives = [](const std::string& text) {
    try {
      (void)parse_scene(text, "fuzz.toml");
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  };
  for (std::size_t n = 0; n <= kFullScene.size(); ++n) survives(kFullScene.substr(0, n));
  std::mt19937_64 rng(12345);
  const std::string alphabet = "[]{}=,.\"'#\n 0123456789-+eE_xyzinfa";
  for (int round = 0; round < 3000; ++round) {
    std::string text = kFullScene;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits; ++k) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3) {
        case 0: text[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: text.erase(at, 1 + rng() % 8); break;
        default: text.insert(at, 1, static_cast<char>(rng() % 256)); break;
      }
    }
    survives(text);
  }
  survives(std::string(1 << 20, '['));
  survives("a = " + std::string(100000, '['));
  survives("[box]\n" + std::string(1 << 20, 'm') + " = 1\n");
  survives(std::string("\0\xff\xfe[box]", 8));
}

// Block time steps: a fixed largest step, gravity with a softening, open space.
TEST(SceneErrors, BlockTimeStepsNeedAFixedStepGravityAndOpenSpace) {
  const std::string open_nbody =
      minimal("[box]\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\n", "[nbody]\nsoftening = 0.01\n");
  const std::string block = edit(open_nbody, "dt = 0.01", "dt = 0.01\ntime_steps = \"block\"");
  EXPECT_NO_THROW((void)parse_scene(block, "scene.toml"));
  for (const Case& c : std::vector<Case>{
           {"adaptive", edit(block, "dt = 0.01", "dt = \"adaptive\"\ndt_max = 0.01"),
            "simulation.time_steps: \"block\" needs a fixed simulation.dt (the largest step, bin 0), not \"adaptive\""},
           {"no softening", edit(block, "softening = 0.01", "softening = 0"),
            "simulation.time_steps: \"block\" needs [nbody] with nbody.softening > 0: a particle's bin comes from "
            "eta*sqrt(softening/|a|)"},
           {"no gravity", edit(block, "[nbody]\nsoftening = 0.01\n", ""),
            "simulation.time_steps: \"block\" needs [nbody] with nbody.softening > 0: a particle's bin comes from "
            "eta*sqrt(softening/|a|)"},
           {"walls", edit(block, "[nbody]", "[box]\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\n\n[nbody]"),
            "simulation.time_steps: \"block\" needs open space (no [box]): the walls reflect on whole steps"},
           {"max_bin range", edit(block, "time_steps = \"block\"", "time_steps = \"block\"\nmax_bin = 41"),
            "simulation.max_bin: must be in [0, 40], got 41"},
           {"max_bin without block", edit(open_nbody, "dt = 0.01", "dt = 0.01\nmax_bin = 4"),
            "simulation.max_bin: only with simulation.time_steps = \"block\""},
       }) {
    expect_error(c);
  }
}

}  // namespace
}  // namespace swirl::scene
