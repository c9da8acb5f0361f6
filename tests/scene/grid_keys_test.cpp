// The sorted grid's scene keys: sph.grid.cell_order and sph.grid.skin.
#include <gtest/gtest.h>

#include <string>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

const std::string kSph = test::kMinimalScene + "\n[sph]\nsmoothing_length = 0.1\n";

TEST(GridKeys, DefaultsAreRowsWithoutSkin) {
  const Scene s = parse_scene(kSph, "scene.toml");
  ASSERT_TRUE(s.sph);
  EXPECT_EQ(s.sph->cell_order, spatial::CellOrder::Rows);
  EXPECT_EQ(s.sph->grid_skin, 0.0);
  EXPECT_EQ(s.sph->cell_table, spatial::CellTable::Auto);
}

TEST(GridKeys, ReadsCellOrderAndSkin) {
  const Scene s =
      parse_scene(kSph + "[sph.grid]\ncell_order = \"morton\"\nskin = 0.01\ntable = \"hashed\"\n", "scene.toml");
  ASSERT_TRUE(s.sph);
  EXPECT_EQ(s.sph->cell_order, spatial::CellOrder::Morton);
  EXPECT_EQ(s.sph->grid_skin, 0.01);
  EXPECT_EQ(s.sph->cell_table, spatial::CellTable::Hashed);
  // Overrides reach them too, and the scene's hash (its canonical form) sees them.
  const Scene o = parse_scene(kSph, "scene.toml", std::vector<std::string>{"sph.grid.skin=0.02"});
  EXPECT_EQ(o.sph->grid_skin, 0.02);
  EXPECT_NE(scene_hash(s), scene_hash(parse_scene(kSph, "scene.toml")));
  EXPECT_NE(scene_hash(o), scene_hash(parse_scene(kSph, "scene.toml")));
}

TEST(GridKeys, BadValuesNameTheFileKeyAndReason) {
  const std::string order = test::error_of(kSph + "[sph.grid]\ncell_order = \"hilbert\"\n");
  EXPECT_EQ(order.rfind("scene.toml: sph.grid.cell_order: ", 0), 0u) << order;
  EXPECT_NE(order.find("hilbert"), std::string::npos) << order;
  EXPECT_NE(order.find("'rows'"), std::string::npos) << order;
  EXPECT_NE(order.find("'morton'"), std::string::npos) << order;
  const std::string skin = test::error_of(kSph + "[sph.grid]\nskin = -0.01\n");
  EXPECT_EQ(skin.rfind("scene.toml: sph.grid.skin: ", 0), 0u) << skin;
  const std::string inf = test::error_of(kSph + "[sph.grid]\nskin = inf\n");
  EXPECT_EQ(inf.rfind("scene.toml: sph.grid.skin: ", 0), 0u) << inf;
  const std::string table = test::error_of(kSph + "[sph.grid]\ntable = \"sparse\"\n");
  EXPECT_EQ(table.rfind("scene.toml: sph.grid.table: ", 0), 0u) << table;
  const std::string typo = test::error_of(kSph + "[sph.grid]\nskins = 0.01\n");
  EXPECT_NE(typo.find("skins"), std::string::npos) << typo;
}

}  // namespace
}  // namespace swirl::scene
