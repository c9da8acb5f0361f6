// Scenes and helpers shared by the scene module's tests.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "swirl/scene/load.hpp"

namespace swirl::scene::test {

// Every key set, none at its default; three sources, one of each kind.
inline const std::string kFullScene = R"(# a full scene
[simulation]
precision = "double"
dt = 0.001
end_time = 0.5
block_size = 256

[box]
min = [0, 0, 0]
max = [1, 1, 1]
restitution = 0.25

[forces]
gravity = [0, -1, -9.81]

[output]
interval = 0.05
format = ["csv", "vtp"]

[[particles]]
kind = "lattice"
min = [0.1, 0.1, 0.1]
max = [0.5, 0.5, 0.5]
spacing = 0.1
jitter = 0.2
seed = 7
mass = 0.001
velocity = [1, 0, 0]

[[particles]]
kind = "random"
min = [0.6, 0.6, 0.6]
max = [0.9, 0.9, 0.9]
count = 100
seed = 3
mass = 0.002
velocity = [0, 0, -1]

[[particles]]
kind = "list"
positions = [[0.5, 0.5, 0.9], [0.25, 0.75, 0.5]]
velocities = [[0, 0, 1], [1, 1, 1]]
masses = [0.5, 1.5]
)";

// Only the required keys.
inline const std::string kMinimalScene = R"(
[simulation]
dt = 0.01
steps = 10

[box]
min = [-1, -1, -1]
max = [1, 1, 1]

[[particles]]
kind = "list"
positions = [[0, 0, 0]]
mass = 1
)";

// `text` with the first `from` replaced by `to`; fails the test if `from` is absent.
inline std::string edit(std::string text, std::string_view from, std::string_view to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test scene lacks '" << from << "'";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The SceneError message parse_scene gives for `text` (file "scene.toml"), or
// "<no error>" when it loads.
inline std::string error_of(const std::string& text, std::vector<std::string> overrides = {}) {
  try {
    (void)parse_scene(text, "scene.toml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<no error>";
}

}  // namespace swirl::scene::test
