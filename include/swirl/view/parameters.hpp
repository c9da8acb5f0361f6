// The live parameters of `swirl view SCENE`: what a page's sliders may change
// while the scene runs (docs/view.md, "Live parameters").
//
//   sph.viscosity    μ of the SPH fluid (Pa·s)            scenes with [sph]
//   forces.gravity   g of the uniform field (m/s²)         scenes with [sph] or a uniform field
//   nbody.softening  Plummer ε of self-gravity             scenes with [nbody], global time steps
//
// Each is described by its scene key's declaration (scene/keys.hpp): its name,
// unit and range. A value outside the declared range is refused, as the scene
// loader would refuse it. Where the declaration has no upper bound (all three
// today) the view sets one, which the page's slider spans and the session
// enforces alike: ten times the scene's value for μ and ε (at least 1 Pa·s,
// at least a tenth of the particles' initial extent), four times |g| for
// gravity (4 × 9.81 m/s² when the scene's g is 0), so a slider cannot throw the run into a
// blow-up by a stray drag to an absurd value. Gravity's range bounds |g|; any
// direction is allowed.
//
// Softening is not offered with block time steps: their bin condition
// (integrate/block_steps.hpp) keeps the scene's ε.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "swirl/core/vec3.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/view/wire.hpp"

namespace swirl::view {

struct LiveParameter {
  control::ParameterId id = control::ParameterId::Viscosity;
  std::string key;    // the scene key: "sph.viscosity"
  std::string label;  // for the page: "viscosity"
  std::string unit;   // the key's unit: "Pa·s"
  bool vector = false;          // gravity: a vector whose magnitude lies in the range
  double lo = 0, hi = 0;        // the accepted values (a vector's magnitude): [lo, hi], lo excluded when lo_open
  bool lo_open = false;
  std::string declared;         // the key's declared range as the docs write it (">= 0"), "" when unbounded
  Vec3d value{};                // the current value (a scalar in x)
};

// The parameters a scene offers, with the scene's values. `extent`: the
// largest side of the initial particles' bounds (the softening's scale when
// the scene's ε is 0).
std::vector<LiveParameter> live_parameters(const scene::Scene& scene, double extent);

// Why `value` cannot be `p`'s new value ("" when it can).
std::string refusal(const LiveParameter& p, const Vec3d& value);

// `scene` with `p`'s value set to `value` (what a reset rebuilds from).
void set_in_scene(scene::Scene& scene, const LiveParameter& p, const Vec3d& value);

// "0.5 Pa·s", "(0, 0, -9.81) m/s²".
std::string value_text(const LiveParameter& p, const Vec3d& value);

// The parameters as a JSON array of objects (the hello's "parameters"):
// id, key, label, unit, vector, min, max, min_open, declared, value.
std::string parameters_json(const std::vector<LiveParameter>& parameters);
// Their current values as a JSON object keyed by the scene key (statuses).
std::string parameter_values_json(const std::vector<LiveParameter>& parameters);

}  // namespace swirl::view
