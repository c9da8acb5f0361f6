// One input of the scene fuzzer, through the real API: parse_scene() with an
// optional override, then what `swirl run` does next with an accepted scene
// (scene_hash, total_steps, and make_particles when the scene is small), and
// what `swirl run --resume` does: reload the effective scene it saved
// (Scene::toml), which must give the same scene (the same scene_hash).
//
// Input format: the bytes are the scene's TOML text. If they start with
// "#set ", the rest of that first line is also passed as one override
// (KEY=VALUE, as `swirl run --set`); being a TOML comment, the line does not
// change the scene text itself, so every seed stays a valid scene file.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz/replay.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::fuzz {

inline constexpr std::string_view kSceneName = "fuzz.toml";
// Scenes up to this many particles are also built, as `swirl run` would.
inline constexpr std::size_t kBuildLimit = 2000;

inline std::vector<std::string> scene_overrides(std::string_view bytes) {
  constexpr std::string_view prefix = "#set ";
  if (bytes.substr(0, prefix.size()) != prefix) return {};
  std::string_view line = bytes.substr(prefix.size());
  line = line.substr(0, line.find('\n'));
  return {std::string(line)};
}

template <class Real>
void check_particles(const scene::Scene& s, std::size_t expected) {
  const ParticleSet<Real> p = scene::make_particles<Real>(s);
  require(p.size() == expected, "make_particles made a different count than count_particles");
  for (std::size_t i = 0; i < p.size(); ++i) {
    require(p.id[i] == i, "particle ids are not 0..N-1");
    const Vec3<Real> x = p.position.get(i), v = p.velocity.get(i);
    // A scene that passed validation must give particles a solver can use.
    require(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z), "accepted scene makes a non-finite position");
    require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z), "accepted scene makes a non-finite velocity");
    require(std::isfinite(p.mass[i]) && p.mass[i] > 0, "accepted scene makes a mass that is not finite and > 0");
  }
}

// Returns the SceneError message, or nullopt if the scene was accepted. With
// `strict`, the particles of an accepted small scene must also be finite.
inline std::optional<std::string> replay_scene(std::string_view bytes, bool strict = false) {
  const std::vector<std::string> overrides = scene_overrides(bytes);
  try {
    const scene::Scene s = scene::parse_scene(bytes, kSceneName, overrides);
    const std::uint64_t hash = scene::scene_hash(s);
    (void)s.total_steps();
    // `swirl run --resume` reloads the effective scene from the scene.toml
    // written from s.toml, and checks its hash against the checkpoint's.
    try {
      const scene::Scene again = scene::parse_scene(s.toml, kSceneName);
      require(scene::scene_hash(again) == hash, "the effective scene (Scene::toml) loads as a different scene",
              s.toml.substr(0, 2000));
    } catch (const scene::SceneError& e) {
      throw ContractViolation(std::string("the effective scene (Scene::toml) is refused: ") + e.what() + "\n" +
                              s.toml.substr(0, 2000));
    }
    const std::size_t n = scene::count_particles(s);
    require(n >= 1, "accepted scene without particles");
    if (n <= kBuildLimit) {
      if (strict) {
        if (s.precision == scene::Precision::Float) check_particles<float>(s, n);
        else check_particles<double>(s, n);
      } else {
        if (s.precision == scene::Precision::Float) (void)scene::make_particles<float>(s);
        else (void)scene::make_particles<double>(s);
      }
    }
  } catch (const scene::SceneError& e) {
    const std::string_view message = e.what();
    check_error_message(message, kSceneName);
    // docs/scenes.md: "refused with one line".
    require(message.find('\n') == std::string_view::npos, "SceneError message is not one line", message);
    return std::string(message);
  }
  return std::nullopt;
}

}  // namespace swirl::fuzz
