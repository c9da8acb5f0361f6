// docs/scenes.md's key tables are the ones the key declarations generate
// (scene/keys.hpp); regenerate with `build/scene_keys_doc --write docs/scenes.md`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/keys.hpp"

namespace swirl::scene {
namespace {

std::string scenes_md() {
  const auto path = std::filesystem::path(SWIRL_SOURCE_DIR) / "docs" / "scenes.md";
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot read " << path;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(KeysDoc, DocsTablesAreTheGeneratedOnes) {
  const std::string doc = scenes_md();
  std::string generated;
  ASSERT_NO_THROW(generated = with_generated_key_tables(doc));
  EXPECT_EQ(generated, doc) << "docs/scenes.md's key tables are stale: run build/scene_keys_doc --write docs/scenes.md";
}

TEST(KeysDoc, AStaleOrMissingTableIsFound) {
  const std::string doc = scenes_md();
  // A default edited by hand differs from the declaration's.
  const std::string stale = test::edit(doc, "| `restitution` | number | – | `0.5` |", "| `restitution` | number | – | `0.6` |");
  EXPECT_NE(with_generated_key_tables(stale), stale);
  // A region removed is an error, not a silent pass.
  const std::string marker = "<!-- scene-keys:nbody ";
  const auto at = doc.find(marker);
  ASSERT_NE(at, std::string::npos);
  std::string without = doc;
  without.replace(at, marker.size(), "<!-- removed ");
  EXPECT_THROW((void)with_generated_key_tables(without), std::runtime_error);
}

TEST(KeysDoc, EveryDeclaredKeyIsInItsSectionsTable) {
  for (const auto& spec : scene_keys()) {
    const std::string section(spec.section.empty() ? "format" : spec.section);
    std::string shown(spec.key);
    if (shown.starts_with(section + ".")) shown.erase(0, section.size() + 1);
    EXPECT_NE(key_table_markdown(section).find("| `" + shown + "` |"), std::string::npos) << spec.key;
  }
  for (const auto& kind : source_kinds())
    for (const auto& spec : kind.keys)
      EXPECT_NE(key_table_markdown(kind.name).find("| `" + std::string(spec.key) + "` |"), std::string::npos)
          << kind.name << "." << spec.key;
}

// The scene fuzzer's dictionary (tests/fuzz/scene.dict) names every key and
// every source kind, so that libFuzzer's mutations reach the newest keys too.
TEST(KeysDoc, TheFuzzDictionaryNamesEveryKey) {
  const auto path = std::filesystem::path(SWIRL_SOURCE_DIR) / "tests" / "fuzz" / "scene.dict";
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << "cannot read " << path;
  const std::string dict{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto expect_named = [&](std::string_view dotted) {
    const std::string leaf(dotted.substr(dotted.rfind('.') + 1));
    EXPECT_NE(dict.find("=\"" + leaf + "\""), std::string::npos) << "tests/fuzz/scene.dict lacks " << dotted;
  };
  for (const auto& spec : scene_keys()) expect_named(spec.key);
  for (const auto& spec : probe_keys()) expect_named(spec.key);
  for (const auto& spec : inlet_keys()) expect_named(spec.key);
  for (const auto& spec : outlet_keys()) expect_named(spec.key);
  for (const auto& kind : source_kinds()) {
    EXPECT_NE(dict.find("\\\"" + std::string(kind.name) + "\\\""), std::string::npos)
        << "tests/fuzz/scene.dict lacks the kind \"" << kind.name << "\" (as str_NAME=\"\\\"NAME\\\"\")";
    for (const auto& spec : kind.keys) expect_named(spec.key);
  }
}

}  // namespace
}  // namespace swirl::scene
