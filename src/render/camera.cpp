#include "swirl/render/camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace swirl::render {
namespace {

Vec3d normalized(const Vec3d& v) { return v * (1.0 / norm(v)); }
std::array<Vec3d, 8> corners(const Box<double>& b) {
  std::array<Vec3d, 8> c;
  for (int i = 0; i < 8; ++i) c[i] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
  return c;
}

// Perspective: the eye stands this many bounding radii from the centre (a mild
// perspective, about a 40° field of view over the scene).
constexpr double kEyeDistanceInRadii = 2.8;
// Fraction of the picture region the scene fills.
constexpr double kFill = 0.92;

}  // namespace

void view_axes(View view, Vec3d& forward, Vec3d& right, Vec3d& up) {
  switch (view) {
    case View::Front: forward = {0, 1, 0}; right = {1, 0, 0}; up = {0, 0, 1}; return;
    case View::Top: forward = {0, 0, -1}; right = {1, 0, 0}; up = {0, 1, 0}; return;
    case View::Iso:
      // From the front-right and above, so x still runs mostly to the right.
      forward = normalized(Vec3d{-0.8, 1.6, -1.0});
      right = normalized(cross(forward, Vec3d{0, 0, 1}));
      up = cross(right, forward);
      return;
  }
}

Camera Camera::fit(const Box<double>& bounds, View view, Projection projection, double x0, double y0,
                   double width, double height) {
  Camera c;
  c.projection = projection;
  view_axes(view, c.forward, c.right, c.up);
  const Vec3d centre = (bounds.lo + bounds.hi) * 0.5;
  const double radius = std::max(0.5 * norm(bounds.hi - bounds.lo), 1e-12);
  double umin = std::numeric_limits<double>::max(), umax = -umin, vmin = umin, vmax = -umin;
  if (projection == Projection::Perspective) c.distance = kEyeDistanceInRadii * radius;
  const Vec3d eye = centre - c.forward * c.distance;
  for (const Vec3d& p : corners(bounds)) {
    double u, v;
    if (projection == Projection::Orthographic) {
      u = dot(p - centre, c.right);
      v = dot(p - centre, c.up);
    } else {
      const double depth = dot(p - eye, c.forward);
      u = dot(p - eye, c.right) / depth;
      v = dot(p - eye, c.up) / depth;
    }
    umin = std::min(umin, u); umax = std::max(umax, u);
    vmin = std::min(vmin, v); vmax = std::max(vmax, v);
  }
  const double tiny = projection == Projection::Orthographic ? 1e-12 * radius : 1e-12;
  const double s = kFill * std::min(width / std::max(umax - umin, tiny), height / std::max(vmax - vmin, tiny));
  c.target = centre;
  if (projection == Projection::Orthographic) {
    c.scale = s;
    c.target = centre + c.right * (0.5 * (umin + umax)) + c.up * (0.5 * (vmin + vmax));
    c.centre_x = x0 + 0.5 * width;
    c.centre_y = y0 + 0.5 * height;
  } else {
    c.focal = s;
    c.centre_x = x0 + 0.5 * width - s * 0.5 * (umin + umax);
    c.centre_y = y0 + 0.5 * height + s * 0.5 * (vmin + vmax);
  }
  return c;
}

std::optional<Projected> Camera::project(const Vec3d& p) const {
  if (projection == Projection::Orthographic) {
    const Vec3d rel = p - target;
    return Projected{centre_x + scale * dot(rel, right), centre_y - scale * dot(rel, up), dot(rel, forward), scale};
  }
  const Vec3d rel = p - (target - forward * distance);
  const double depth = dot(rel, forward);
  if (!(depth > 1e-6 * distance)) return std::nullopt;
  const double ppu = focal / depth;
  return Projected{centre_x + ppu * dot(rel, right), centre_y - ppu * dot(rel, up), depth, ppu};
}

View parse_view(std::string_view name) {
  if (name == "front") return View::Front;
  if (name == "top") return View::Top;
  if (name == "iso") return View::Iso;
  throw std::invalid_argument("unknown view '" + std::string(name) + "' (front, top or iso)");
}

Projection parse_projection(std::string_view name) {
  if (name == "ortho" || name == "orthographic") return Projection::Orthographic;
  if (name == "perspective") return Projection::Perspective;
  throw std::invalid_argument("unknown projection '" + std::string(name) + "' (ortho or perspective)");
}

}  // namespace swirl::render
