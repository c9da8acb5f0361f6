// The scene format version (root key `format`), the unit system
// (simulation.units, nbody.G) and forces.damping.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

using test::error_of;
using test::kMinimalScene;

const std::string kGravity = R"(
[simulation]
dt = 0.01
steps = 10

[nbody]
opening = 0.5

[[particles]]
kind = "plummer"
count = 100
)";

const std::string kSphScene = R"(
[simulation]
dt = 0.001
steps = 10

[box]
min = [0, 0, 0]
max = [1, 1, 1]

[sph]
smoothing_length = 0.05

[[particles]]
kind = "fluid_block"
min = [0.2, 0.2, 0.2]
max = [0.4, 0.4, 0.4]
spacing = 0.05
)";

Scene parse(const std::string& text, std::vector<std::string> overrides = {}) {
  return parse_scene(text, "scene.toml", overrides);
}

TEST(SceneFormat, AbsentMeansTheCurrentFormat) {
  EXPECT_EQ(parse(kMinimalScene).format_version, kSceneFormatVersion);
  EXPECT_EQ(parse("format = 1\n" + kMinimalScene).format_version, 1u);
  // The version does not change what the scene computes, so not its hash.
  EXPECT_EQ(scene_hash(parse("format = 1\n" + kMinimalScene)), scene_hash(parse(kMinimalScene)));
}

TEST(SceneFormat, ANewerFormatIsRefusedBeforeItsKeys) {
  // A newer file may hold sections this build does not know: the version is the reason.
  EXPECT_EQ(error_of("format = 2\n" + kMinimalScene + "[fields]\nx = 1\n"),
            "scene.toml: format: the scene is of format 2, newer than this swirl reads (formats 1 to 1): use a newer swirl");
  EXPECT_EQ(error_of("format = 0\n" + kMinimalScene), "scene.toml: format: must be >= 1 (the first scene format), got 0");
  EXPECT_EQ(error_of("format = \"1\"\n" + kMinimalScene), "scene.toml: format: expected an integer, got a string");
  EXPECT_EQ(error_of(kMinimalScene, {"format=3"}).find("scene.toml: format: the scene is of format 3"), 0u);
}

TEST(SceneUnits, DefaultFollowsTheSections) {
  const Scene gravity = parse(kGravity);
  EXPECT_EQ(gravity.units, Units::NBody);
  EXPECT_EQ(gravity.gravitational_constant, 1.0);
  const Scene fluid = parse(kSphScene);
  EXPECT_EQ(fluid.units, Units::SI);
  EXPECT_EQ(fluid.gravitational_constant, kGravitationalConstantSI);
  // Self-gravity with a fluid: SI.
  const Scene both = parse(kSphScene + "[nbody]\nopening = 0.5\n");
  EXPECT_EQ(both.units, Units::SI);
  EXPECT_EQ(both.gravitational_constant, 6.67430e-11);
  EXPECT_EQ(parse(kMinimalScene).units, Units::SI);
}

TEST(SceneUnits, ExplicitUnitsAndG) {
  const Scene si = parse(kGravity, {"simulation.units=\"si\""});
  EXPECT_EQ(si.units, Units::SI);
  EXPECT_EQ(si.gravitational_constant, kGravitationalConstantSI);
  const Scene g = parse(kGravity, {"nbody.G=4.5"});
  EXPECT_EQ(g.units, Units::NBody);
  EXPECT_EQ(g.gravitational_constant, 4.5);
  EXPECT_EQ(error_of(kGravity, {"nbody.G=0"}), "scene.toml: nbody.G: must be > 0, got 0");
  EXPECT_EQ(error_of(kGravity, {"nbody.G=-1"}), "scene.toml: nbody.G: must be > 0, got -1");
  EXPECT_EQ(error_of(kGravity, {"simulation.units=\"cgs\""}),
            "scene.toml: simulation.units: unknown unit system 'cgs' (allowed: 'si', 'nbody')");
  EXPECT_EQ(error_of(kGravity, {"nbody.g=2"}), "scene.toml: nbody.g: unknown key (did you mean 'G'?)");
}

TEST(SceneUnits, GAndUnitsAreHashed) {
  const auto base = scene_hash(parse(kGravity));
  EXPECT_NE(scene_hash(parse(kGravity, {"nbody.G=2"})), base);
  EXPECT_NE(scene_hash(parse(kGravity, {"simulation.units=\"si\""})), base);
  // Giving the default explicitly is the same scene.
  EXPECT_EQ(scene_hash(parse(kGravity, {"nbody.G=1"})), base);
  EXPECT_EQ(scene_hash(parse(kGravity, {"simulation.units=\"nbody\""})), base);
}

TEST(SceneDamping, ReadValidatedAndHashed) {
  EXPECT_EQ(parse(kMinimalScene).damping, 0.0);
  EXPECT_EQ(parse(kMinimalScene, {"forces.damping=0.5"}).damping, 0.5);
  EXPECT_EQ(error_of(kMinimalScene, {"forces.damping=-1"}), "scene.toml: forces.damping: must be >= 0, got -1");
  EXPECT_EQ(error_of(kMinimalScene, {"forces.dampign=1"}), "scene.toml: forces.dampign: unknown key (did you mean 'damping'?)");
  EXPECT_NE(scene_hash(parse(kMinimalScene, {"forces.damping=0.5"})), scene_hash(parse(kMinimalScene)));
}

}  // namespace
}  // namespace swirl::scene
