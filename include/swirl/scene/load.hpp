// Loading and validating scene files.
//
// Scene file format (TOML; every key listed in docs/scenes.md):
//
//   [simulation]  precision = "float" | "double", dt, end_time | steps, block_size
//   [box]         min = [x, y, z], max = [x, y, z], restitution
//   [forces]      gravity = [gx, gy, gz]
//   [output]      interval, format = "vtp" | "csv" | ["vtp", "csv"]
//   [[particles]] kind = "lattice" | "random" | "list", and the kind's keys
//
// Unknown keys are errors that suggest the closest known key.
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
// form), so a checkpoint can tell which scene it belongs to.
std::uint64_t scene_hash(const Scene& scene);

}  // namespace swirl::scene
