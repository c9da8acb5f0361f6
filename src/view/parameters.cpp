#include "swirl/view/parameters.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "json.hpp"
#include "swirl/scene/keys.hpp"

namespace swirl::view {
namespace {

const scene::KeySpec<scene::Scene>& key_spec(std::string_view key) {
  for (const auto& k : scene::scene_keys())
    if (k.key == key) return k;
  throw std::logic_error(fmt::format("swirl view: no scene key '{}'", key));
}

// A parameter from its key's declaration; `view_hi` bounds it where the key does not.
LiveParameter from_key(control::ParameterId id, std::string_view key, std::string label, bool vector, double view_hi,
                       Vec3d value) {
  const auto& spec = key_spec(key);
  LiveParameter p;
  p.id = id;
  p.key = std::string(key);
  p.label = std::move(label);
  p.unit = std::string(spec.unit);
  p.vector = vector;
  p.declared = spec.range.text();
  // A vector key's range bounds each component; the view bounds the magnitude, from 0.
  p.lo = vector ? 0.0 : (std::isfinite(spec.range.lo) ? spec.range.lo : -view_hi);
  p.lo_open = !vector && spec.range.lo_open;
  p.hi = (!vector && std::isfinite(spec.range.hi)) ? spec.range.hi : view_hi;
  p.value = value;
  return p;
}

double magnitude(const Vec3d& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

}  // namespace

std::vector<LiveParameter> live_parameters(const scene::Scene& scene, double extent) {
  using control::ParameterId;
  std::vector<LiveParameter> out;
  if (scene.sph) {
    const double mu = scene.sph->viscosity;
    out.push_back(from_key(ParameterId::Viscosity, "sph.viscosity", "viscosity", false, std::max(10 * mu, 1.0), {mu, 0, 0}));
  }
  if (scene.sph || !(scene.gravity == Vec3d{})) {
    const double g = magnitude(scene.gravity);
    out.push_back(from_key(ParameterId::Gravity, "forces.gravity", "gravity", true, 4 * (g > 0 ? g : 9.81), scene.gravity));
  }
  if (scene.nbody && scene.time_steps == scene::TimeSteps::Global) {
    const double eps = scene.nbody->softening;
    const double scale = std::isfinite(extent) && extent > 0 ? 0.1 * extent : 1.0;
    out.push_back(from_key(ParameterId::Softening, "nbody.softening", "softening", false, std::max(10 * eps, scale),
                           {eps, 0, 0}));
  }
  return out;
}

std::string refusal(const LiveParameter& p, const Vec3d& value) {
  if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z)) return "a value is not finite";
  const double v = p.vector ? magnitude(value) : value.x;
  if (!p.vector && (value.y != 0 || value.z != 0)) return fmt::format("{} is a scalar", p.key);
  const bool above_lo = p.lo_open ? v > p.lo : v >= p.lo;
  if (!above_lo || v > p.hi)
    return fmt::format("{}{} = {:.6g} {} is outside {}{:.6g}, {:.6g}]{}", p.key, p.vector ? " magnitude" : "", v, p.unit,
                       p.lo_open ? "(" : "[", p.lo, p.hi,
                       p.declared.empty() ? std::string() : fmt::format(" (the key's range: {})", p.declared));
  return {};
}

void set_in_scene(scene::Scene& scene, const LiveParameter& p, const Vec3d& value) {
  switch (p.id) {
    case control::ParameterId::Viscosity:
      if (scene.sph) scene.sph->viscosity = value.x;
      break;
    case control::ParameterId::Gravity: scene.gravity = value; break;
    case control::ParameterId::Softening:
      if (scene.nbody) scene.nbody->softening = value.x;
      break;
  }
}

std::string value_text(const LiveParameter& p, const Vec3d& value) {
  if (p.vector) return fmt::format("({:.6g}, {:.6g}, {:.6g}) {}", value.x, value.y, value.z, p.unit);
  return fmt::format("{:.6g} {}", value.x, p.unit);
}

namespace {
std::string value_json(const LiveParameter& p) {
  if (p.vector) return fmt::format("[{},{},{}]", json::number(p.value.x), json::number(p.value.y), json::number(p.value.z));
  return json::number(p.value.x);
}
}  // namespace

std::string parameters_json(const std::vector<LiveParameter>& parameters) {
  std::string out = "[";
  for (const auto& p : parameters) {
    if (out.size() > 1) out += ',';
    out += fmt::format(R"({{"id":{},"key":{},"label":{},"unit":{},"vector":{},"min":{},"max":{},"min_open":{},"declared":{},"value":{}}})",
                       int(p.id), json::string(p.key), json::string(p.label), json::string(p.unit),
                       json::boolean(p.vector), json::number(p.lo), json::number(p.hi), json::boolean(p.lo_open),
                       json::string(p.declared), value_json(p));
  }
  return out + "]";
}

std::string parameter_values_json(const std::vector<LiveParameter>& parameters) {
  std::string out = "{";
  for (const auto& p : parameters) {
    if (out.size() > 1) out += ',';
    out += json::string(p.key) + ":" + value_json(p);
  }
  return out + "}";
}

}  // namespace swirl::view
