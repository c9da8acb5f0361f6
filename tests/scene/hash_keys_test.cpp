// The scene hash covers every declared key: changing any one key's value
// changes the hash (scene/keys.hpp declares which keys exist).
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "swirl/scene/keys.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

// A value of the same type that differs from `value`.
template <class Owner>
KeyValue changed(const KeySpec<Owner>& spec, const KeyValue& value) {
  return std::visit(
      [&]<class T>(const T& v) -> KeyValue {
        if constexpr (std::is_same_v<T, double>) return v * 0.5 + 0.125;  // no fixed point among the defaults (0.25 is)
        else if constexpr (std::is_same_v<T, std::uint64_t>) return v + 1;
        else if constexpr (std::is_same_v<T, bool>) return !v;
        else if constexpr (std::is_same_v<T, std::string_view>) {
          if (spec.type == KeyType::Text) return std::string_view(v == "/a" ? "/b" : "/a");  // a path
          return spec.names.at(spec.names.at(0) == v ? 1 : 0);
        }
        else if constexpr (std::is_same_v<T, Vec3d>) return Vec3d{v.x + 1, v.y, v.z};
        else if constexpr (std::is_same_v<T, std::vector<std::string_view>>) return std::vector{spec.names.back()};
        else if constexpr (std::is_same_v<T, std::vector<Vec3d>>) return std::vector<Vec3d>{{1, 2, 3}};
        else return std::vector<double>{0.125};
      },
      value);
}

TEST(SceneHashKeys, EverySectionKeyChangesTheHash) {
  Scene base;
  base.dt = 0.01;
  base.steps = 10;
  base.sph.emplace();
  base.nbody.emplace();
  base.random_box.emplace();
  base.sources.emplace_back(LatticeSource{});
  int checked = 0;
  for (const auto& spec : scene_keys()) {
    const auto value = spec.get(base);
    if (!spec.hashed || !spec.set || !value) continue;
    Scene other = base;
    spec.set(other, changed(spec, *value));
    EXPECT_NE(scene_hash(other), scene_hash(base)) << spec.key;
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

// A key added after checkpoints existed names its old behaviour's value: it must
// be the key's default, spelt as the value reads, or old scenes change hash.
TEST(SceneHashKeys, LaterKeysLeaveTheirDefaultOutOfTheHash) {
  Scene base;
  base.sph.emplace();
  base.nbody.emplace();
  int checked = 0;
  for (const auto& spec : scene_keys()) {
    if (spec.unhashed_value.empty()) continue;
    const auto value = spec.get(base);
    ASSERT_TRUE(value) << spec.key;
    const std::string text = value_text(*value, true);
    const std::string quoted = std::string(1, '"').append(spec.unhashed_value).append(1, '"');
    EXPECT_TRUE(text == spec.unhashed_value || text == quoted)
        << spec.key << ": default " << text << ", left out of the hash: " << spec.unhashed_value;
    ++checked;
  }
  EXPECT_GE(checked, 5);
}

TEST(SceneHashKeys, EverySourceKeyChangesTheHash) {
  for (const auto& kind : source_kinds()) {
    Scene base;
    base.sources.push_back(kind.prototype);
    for (const auto& spec : kind.keys) {
      const auto value = spec.get(base.sources[0]);
      if (!spec.hashed || !spec.set || !value) continue;
      Scene other = base;
      spec.set(other.sources[0], changed(spec, *value));
      EXPECT_NE(scene_hash(other), scene_hash(base)) << kind.name << "." << spec.key;
    }
  }
}

// Keys without a field of their own are folded into one that is hashed.
TEST(SceneHashKeys, DerivedKeysAreHashedThroughTheirField) {
  const std::string scene = R"(
[simulation]
dt = "adaptive"
dt_max = 0.01
end_time = 1
[box]
min = [0, 0, 0]
max = [1, 1, 1]
[[particles]]
kind = "list"
positions = [[0.5, 0.5, 0.5]]
mass = 1
)";
  const auto base = scene_hash(parse_scene(scene, "s.toml"));
  EXPECT_NE(scene_hash(parse_scene(scene, "s.toml", std::vector<std::string>{"simulation.dt_max=0.02"})), base);
  EXPECT_NE(scene_hash(parse_scene(scene, "s.toml", std::vector<std::string>{"simulation.dt_min=0.001"})), base);
  EXPECT_NE(scene_hash(parse_scene(scene, "s.toml", std::vector<std::string>{"particles.0.mass=2"})), base);
}

}  // namespace
}  // namespace swirl::scene
