// validate() on a Scene built in code: refused like the same scene in a file,
// with the key's name and the reason.
#include <gtest/gtest.h>

#include <string>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/scene/validate.hpp"

namespace swirl::scene {
namespace {

// One particle at rest in a unit box, 10 steps of 0.01 s.
Scene small_scene() {
  Scene s;
  s.dt = 0.01;
  s.steps = 10;
  s.box = {{0, 0, 0}, {1, 1, 1}};
  ListSource list;
  list.positions = {{0.5, 0.5, 0.5}};
  list.masses = {1};
  s.sources.emplace_back(list);
  return s;
}

std::string refusal(const Scene& s) {
  try {
    validate(s);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<accepted>";
}

TEST(Validate, AcceptsAValidSceneBuiltInCode) { EXPECT_EQ(refusal(small_scene()), "<accepted>"); }

TEST(Validate, RefusesBadValuesNamingTheKey) {
  Scene s = small_scene();
  s.dt = -1;
  EXPECT_EQ(refusal(s), "scene: simulation.dt: must be > 0, got -1");
  s = small_scene();
  s.file = "built.toml";
  s.restitution = 2;
  EXPECT_EQ(refusal(s), "built.toml: box.restitution: must be in [0, 1], got 2");
  s = small_scene();
  s.damping = -0.5;
  EXPECT_EQ(refusal(s), "scene: forces.damping: must be >= 0, got -0.5");
  s = small_scene();
  s.block_size = 0;
  EXPECT_EQ(refusal(s), "scene: simulation.block_size: must be >= 1, got 0");
  s = small_scene();
  s.gravity.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(refusal(s), "scene: forces.gravity[1]: must be finite, got nan");
}

TEST(Validate, RefusesEnumsWithoutAName) {
  Scene s = small_scene();
  s.precision = static_cast<Precision>(7);
  EXPECT_EQ(refusal(s), "scene: simulation.precision: is not a valid precision (allowed: 'float', 'double')");
}

TEST(Validate, AppliesTheRulesBetweenKeys) {
  Scene s = small_scene();
  s.end_time = 1.0;
  EXPECT_EQ(refusal(s), "scene: simulation.steps: cannot be given together with simulation.end_time; give one of them");
  s = small_scene();
  s.steps.reset();
  EXPECT_EQ(refusal(s), "scene: simulation.end_time: missing required key (give end_time or simulation.steps)");
  s = small_scene();
  s.box.hi.z = 0;
  EXPECT_EQ(refusal(s), "scene: box.max: must be greater than box.min on every axis, but along z 0 <= 0");
  s = small_scene();
  s.sources.clear();
  EXPECT_EQ(refusal(s), "scene: particles: no particles: the scene needs at least one [[particles]] source");
  s = small_scene();
  std::get<ListSource>(s.sources[0]).positions[0].x = 2;
  EXPECT_EQ(refusal(s), "scene: particles[0].positions[0]: (2, 0.5, 0.5) lies outside the box [(0, 0, 0), (1, 1, 1)]");
  s = small_scene();
  std::get<ListSource>(s.sources[0]).masses.push_back(2);
  EXPECT_EQ(refusal(s), "scene: particles[0].masses: has 2 entries but particles[0].positions has 1");
  s = small_scene();
  std::get<ListSource>(s.sources[0]).masses[0] = 0;
  EXPECT_EQ(refusal(s), "scene: particles[0].masses[0]: must be > 0, got 0");
  s = small_scene();
  s.nbody.emplace();
  s.nbody->scheme = gravity::Scheme::Subtree;  // the linear tree needs the global scheme
  EXPECT_EQ(refusal(s), "scene: nbody.tree: \"linear\" needs nbody.scheme = \"global\" (the paper's scheme "
                        "\"subtree\" walks the paper's tree)");
  s = small_scene();
  s.nbody.emplace();
  s.gravitational_constant = 0;
  EXPECT_EQ(refusal(s), "scene: nbody.G: must be > 0, got 0");
  s = small_scene();  // without [nbody] G is no key, but still checked
  s.gravitational_constant = -1;
  EXPECT_EQ(refusal(s), "scene: nbody.G: must be finite and > 0, got -1");
}

TEST(Validate, RefusesAFormatNewerThanThisBuild) {
  Scene s = small_scene();
  s.format_version = kSceneFormatVersion + 1;
  EXPECT_NE(refusal(s).find("scene: format: the scene is of format 2, newer than this swirl reads"), std::string::npos)
      << refusal(s);
}

// The file path calls validate() too: a loaded scene passes it unchanged.
TEST(Validate, LoadedScenesPass) {
  EXPECT_NO_THROW(validate(parse_scene(test::kFullScene, "full.toml")));
  EXPECT_NO_THROW(validate(parse_scene(test::kMinimalScene, "minimal.toml")));
}

}  // namespace
}  // namespace swirl::scene
