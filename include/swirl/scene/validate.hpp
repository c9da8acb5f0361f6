// Validation of a typed Scene: every rule a scene file is checked against,
// for a Scene however it was made (load_scene() calls this too).
//
// Checks each key against its declaration (scene/keys.hpp: finite numbers in
// range, known names), then the rules between keys: exactly one of end_time
// and steps, a box with positive extent and every source inside it, sources
// that make between 1 and 2^31 particles, list arrays of one entry per
// position, the tree options the chosen tree supports, and a format version
// this build reads.
#pragma once

#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// Throws SceneError "FILE: KEY: reason" (FILE is scene.file, or "scene" when
// empty) for the first rule the scene breaks.
void validate(const Scene& scene);

}  // namespace swirl::scene
