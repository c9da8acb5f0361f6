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

// The leaf size's default follows the method: 16 for Barnes–Hut, 64 for the
// FMM (its P2P and M2L cost less with larger leaves); a written value wins.
TEST(WalkKeys, TheBucketSizeDefaultsTo64ForTheFmmOnly) {
  EXPECT_EQ(parse_scene(kNbody, "scene.toml").nbody->bucket_size, 16u);
  const Scene fmm = parse_scene(kNbody + "method = \"fmm\"\n", "scene.toml");
  EXPECT_EQ(fmm.nbody->bucket_size, 64u);
  const Scene written = parse_scene(kNbody + "method = \"fmm\"\nbucket_size = 16\n", "scene.toml");
  EXPECT_EQ(written.nbody->bucket_size, 16u);
  EXPECT_NE(scene_hash(fmm), scene_hash(written));
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
