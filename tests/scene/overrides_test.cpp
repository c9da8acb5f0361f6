// --set overrides: replacing, adding, indexing [[particles]], and bad overrides.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

using test::error_of;
using test::kFullScene;
using test::kMinimalScene;

Scene with(const std::string& text, std::vector<std::string> overrides) {
  return parse_scene(text, "scene.toml", overrides);
}

TEST(Overrides, ReplaceAValue) {
  EXPECT_EQ(with(kFullScene, {"box.restitution=0.9"}).restitution, 0.9);
  EXPECT_EQ(with(kFullScene, {"simulation.precision=\"float\""}).precision, Precision::Float);
  EXPECT_EQ(with(kFullScene, {"output.format=\"csv\""}).formats, std::vector{OutputFormat::Csv});
  EXPECT_EQ(with(kFullScene, {"box.max=[2, 2, 2]"}).box.hi, (Vec3d{2, 2, 2}));
}

TEST(Overrides, ValueTypeMayChange) {
  EXPECT_EQ(with(kFullScene, {"output.format=[\"vtp\"]"}).formats, std::vector{OutputFormat::Vtp});
}

TEST(Overrides, AddAKeyAndMissingTables) {
  const Scene s = with(kMinimalScene, {"simulation.precision=\"double\"", "forces.gravity=[0, 0, -1]", "output.interval=0.5"});
  EXPECT_EQ(s.precision, Precision::Double);
  EXPECT_EQ(s.gravity, (Vec3d{0, 0, -1}));
  EXPECT_EQ(s.output_interval, 0.5);
}

TEST(Overrides, IndexIntoParticles) {
  const Scene s = with(kFullScene, {"particles.1.count=5000", "particles.0.seed=99", "particles.2.masses=[1, 2]"});
  EXPECT_EQ(std::get<RandomSource>(s.sources[1]).count, 5000u);
  EXPECT_EQ(std::get<LatticeSource>(s.sources[0]).seed, 99u);
  EXPECT_EQ(std::get<ListSource>(s.sources[2]).masses, (std::vector{1.0, 2.0}));
}

TEST(Overrides, IndexIntoAValueArray) {
  EXPECT_EQ(with(kFullScene, {"box.max.2=3"}).box.hi, (Vec3d{1, 1, 3}));
  EXPECT_EQ(std::get<ListSource>(with(kFullScene, {"particles.2.positions.1.0=0.125"}).sources[2]).positions[1],
            (Vec3d{0.125, 0.75, 0.5}));
}

TEST(Overrides, ReplaceAWholeSource) {
  const Scene s = with(kFullScene, {"particles.1={kind = \"list\", positions = [[0.5, 0.5, 0.5]], mass = 3}"});
  const auto& list = std::get<ListSource>(s.sources[1]);
  EXPECT_EQ(list.positions, (std::vector<Vec3d>{{0.5, 0.5, 0.5}}));
  EXPECT_EQ(list.masses, std::vector{3.0});
}

TEST(Overrides, AppliedInOrderAndTrimmed) {
  EXPECT_EQ(with(kFullScene, {"box.restitution=0.9", "box.restitution=0.1"}).restitution, 0.1);
  EXPECT_EQ(with(kFullScene, {"  box.restitution  =  0.75  "}).restitution, 0.75);
}

TEST(Overrides, StepsReplacesEndTimeOnlyIfEndTimeGoes) {
  EXPECT_EQ(error_of(kFullScene, {"simulation.steps=10"}),
            "scene.toml: simulation.steps: cannot be given together with simulation.end_time; give one of them");
  EXPECT_EQ(*with(kMinimalScene, {"simulation.steps=20"}).steps, 20u);
}

TEST(Overrides, AreValidatedLikeTheFile) {
  EXPECT_EQ(error_of(kFullScene, {"box.restitution=2"}), "scene.toml: box.restitution: must be in [0, 1], got 2");
  EXPECT_EQ(error_of(kFullScene, {"simulation.dt=-1"}), "scene.toml: simulation.dt: must be > 0, got -1");
  EXPECT_EQ(error_of(kFullScene, {"box.restitutoin=0.9"}),
            "scene.toml: box.restitutoin: unknown key (did you mean 'restitution'?)");
  EXPECT_EQ(error_of(kFullScene, {"solver.kind=\"sph\""}), "scene.toml: solver: unknown section");
  EXPECT_EQ(error_of(kFullScene, {"particles.0.kind=\"grid\""}),
            "scene.toml: particles[0].kind: unknown kind 'grid' (allowed: 'lattice', 'random', 'list', 'fluid_block', 'fluid_sphere', 'fluid_mesh', 'plummer', 'uniform_sphere', 'uniform_cube', 'cold_collapse', 'plummer_collision', 'hernquist', 'nfw', 'king', 'disk_galaxy', 'snapshot', 'obstacle_box', 'obstacle_sphere', 'obstacle_cylinder', 'obstacle_plane', 'obstacle_mesh')");
  EXPECT_EQ(error_of(kFullScene, {"particles.1.count=1e99"}),
            "scene.toml: particles[1].count: expected an integer, got a float");
}

TEST(Overrides, MalformedOverridesAreNamed) {
  for (const auto& [override_text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"box.restitution", "--set 'box.restitution': expected key=value"},
           {"=1", "--set '=1': empty key"},
           {"  = 1", "--set '  = 1': empty key"},
           {"box..min=1", "--set box..min: empty segment in the key"},
           {".box=1", "--set .box: empty segment in the key"},
           {"box.=1", "--set box.: empty segment in the key"},
           {"simulation.precision=double",
            "--set simulation.precision: cannot parse value 'double' (strings need quotes: key=\"text\")"},
           {"box.restitution=", "--set box.restitution: cannot parse value '' (strings need quotes: key=\"text\")"},
           {"box.restitution=0.5 0.6",
            "--set box.restitution: cannot parse value '0.5 0.6' (strings need quotes: key=\"text\")"},
           {"box.restitution=1\nbox = 2",
            "--set box.restitution: cannot parse value '1\\x0abox = 2' (strings need quotes: key=\"text\")"},
           {"particles.3.count=5", "--set particles.3.count: index 3 is out of range: 'particles' has 3 entries"},
           {"particles.99999999999999999999999.count=5",
            "--set particles.99999999999999999999999.count: index 99999999999999999999999 is out of range: 'particles' "
            "has 3 entries"},
           {"particles.count=5", "--set particles.count: 'particles' is an array; expected an index, got 'count'"},
           {"particles.-1.count=5", "--set particles.-1.count: 'particles' is an array; expected an index, got '-1'"},
           {"box.restitution.x=1", "--set box.restitution.x: 'box.restitution' is a float, not a table or an array"},
           {"box.max.3=1", "--set box.max.3: index 3 is out of range: 'box.max' has 3 entries"},
           {"sources.0.kind=\"list\"", "--set sources.0.kind: index 0 is out of range: 'sources' is not in the scene"},
       }) {
    EXPECT_EQ(error_of(kFullScene, {override_text}), "scene.toml: " + expected) << override_text;
  }
}

TEST(Overrides, NoneLeavesTheSceneAsItIs) {
  EXPECT_EQ(scene_hash(with(kFullScene, {})), scene_hash(parse_scene(kFullScene, "other.toml")));
  EXPECT_EQ(scene_hash(with(kFullScene, {"box.restitution=0.25"})), scene_hash(with(kFullScene, {})));
}

}  // namespace
}  // namespace swirl::scene
