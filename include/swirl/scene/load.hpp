// Loading scene files: TOML text to a validated Scene.
//
// Scene file format (TOML; every key is declared in scene/keys.hpp and listed
// in docs/scenes.md):
//
//   format = N    (optional root key: the file format version, 1 today)
//   [simulation]  precision, units = "si" | "nbody", dt, end_time | steps, block_size, time-step control
//   [box]         min = [x, y, z], max = [x, y, z], restitution
//   [forces]      gravity = [gx, gy, gz], damping
//   [output]      interval, format = "vtp" | "csv" | ["vtp", "csv"]
//   [sph], [nbody], [random_box]
//   [[particles]] kind = "lattice" | "random" | "list" | "fluid_block" | a stellar model | "snapshot", and the kind's keys
//
// A "snapshot" source's file is resolved against the folder of `file` (the
// working directory when it names none, as "<dict>" does) and read while the
// scene is loaded; Scene::toml then names it by that absolute path.
//
// Unknown keys are errors that suggest the closest known key. The scene read
// is then checked by validate() (scene/validate.hpp), as a Scene built in code is.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// Reads, overrides and validates a scene file. Each override is "key=value"
// with a dotted key ("box.restitution=0.9", "particles.0.count=5000") and a
// TOML value; it replaces or adds that key before validation.
// Throws SceneError naming the file, the key and the reason.
Scene load_scene(const std::filesystem::path& file, std::span<const std::string> overrides = {});

// As load_scene, from text already in memory; `file` is used in messages only.
Scene parse_scene(std::string_view text, std::string_view file, std::span<const std::string> overrides = {});

// A stable 64-bit hash of the validated scene (FNV-1a over its canonical TOML
// form: every declared key but `format`, docs/scenes.md "Scene hash"), so a
// checkpoint can tell which scene it belongs to.
std::uint64_t scene_hash(const Scene& scene);

}  // namespace swirl::scene
