// Validation of a typed Scene: every rule a scene file is checked against,
// for a Scene however it was made (load_scene() calls this too).
//
// Checks each key against its declaration (scene/keys.hpp: finite numbers in
// range, known names), then the rules between keys: exactly one of end_time
// and steps, a box with positive extent and every source inside it, sources
// that make between 1 and 2^31 particles, list arrays of one entry per
// position, the tree options the chosen tree supports, and a format version
// this build reads.
//
// advisories() names what is valid but likely to hurt a run (zero softening).
#pragma once

#include <string>
#include <vector>

#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// Throws SceneError "FILE: KEY: reason" (FILE is scene.file, or "scene" when
// empty) for the first rule the scene breaks.
void validate(const Scene& scene);

// Warnings for a valid scene, each "FILE: KEY = value: why, and what to do";
// empty when there is nothing to say. The run prints them before it starts.
std::vector<std::string> advisories(const Scene& scene);

// The entries a dense SPH cell table (sph.grid.table = "dense") needs over the
// box: cells of h + skin per axis (Morton order: rounded up to powers of two),
// multiplied; 0 when the scene has no such table. Validation refuses more
// than 2^31; the memory estimate counts them.
double dense_cell_table_keys(const Scene& scene);

}  // namespace swirl::scene
