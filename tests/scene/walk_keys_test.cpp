// The linear tree's walk keys: nbody.walk and nbody.group_size.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

const std::string kNbody = test::kMinimalScene + "\n[nbody]\nopening = 0.5\n";

TEST(WalkKeys, DefaultsAreTheGroupWalkOfTheLinearTree) {
  const Scene s = parse_scene(kNbody, "scene.toml");
  ASSERT_TRUE(s.nbody);
  EXPECT_EQ(s.nbody->walk, gravity::Walk::Group);
  EXPECT_EQ(s.nbody->group_size, 256u);
}

TEST(WalkKeys, ReadsWalkAndGroupSize) {
  const Scene s = parse_scene(kNbody + "walk = \"particle\"\ngroup_size = 64\n", "scene.toml");
  ASSERT_TRUE(s.nbody);
  EXPECT_EQ(s.nbody->walk, gravity::Walk::Particle);
  EXPECT_EQ(s.nbody->group_size, 64u);
  const Scene o = parse_scene(kNbody, "scene.toml", std::vector<std::string>{"nbody.group_size=512"});
  EXPECT_EQ(o.nbody->group_size, 512u);
  EXPECT_NE(scene_hash(o), scene_hash(parse_scene(kNbody, "scene.toml")));
}

TEST(WalkKeys, BadValuesNameTheFileKeyAndReason) {
  const std::string walk = test::error_of(kNbody + "walk = \"bogus\"\n");
  EXPECT_EQ(walk.rfind("scene.toml: nbody.walk: ", 0), 0u) << walk;
  EXPECT_NE(walk.find("'group'"), std::string::npos) << walk;
  const std::string size = test::error_of(kNbody + "group_size = 0\n");
  EXPECT_EQ(size.rfind("scene.toml: nbody.group_size: ", 0), 0u) << size;
  const std::string paper = test::error_of(kNbody + "scheme = \"subdomain\"\nwalk = \"group\"\n");
  EXPECT_EQ(paper.rfind("scene.toml: nbody.walk: ", 0), 0u) << paper;
}

}  // namespace
}  // namespace swirl::scene
