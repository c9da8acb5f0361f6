// The camera: world points to pixel positions, orthographic or perspective.
//
// A camera looks along `forward` with `right` and `up` spanning the picture
// (an orthonormal frame). Orthographic: a point p lands at
//   x = centre_x + scale·(p − target)·right,  y = centre_y − scale·(p − target)·up
// (pixels, y downwards; `scale` in pixels per world unit). Perspective: the eye
// sits at target − distance·forward and a point at depth d = (p − eye)·forward
// is scaled by focal / d instead (focal in pixels). depth() orders points
// along the view (larger is farther) for painter's-algorithm drawing.
#pragma once

#include <optional>
#include <string_view>

#include "swirl/core/box.hpp"
#include "swirl/core/vec3.hpp"

namespace swirl::render {

enum class View { Front, Top, Iso };  // front: along +y, z up; top: along −z, y up; iso: from (+x, −y, +z)
enum class Projection { Orthographic, Perspective };

// A point on the picture.
struct Projected {
  double x = 0, y = 0;          // pixel coordinates (pixel centres at +½)
  double depth = 0;             // along the view, larger is farther
  double pixels_per_unit = 0;   // how big one world unit looks there
};

struct Camera {
  Projection projection = Projection::Orthographic;
  Vec3d forward{0, 1, 0}, right{1, 0, 0}, up{0, 0, 1};
  Vec3d target{};                 // world point at the picture's centre
  double centre_x = 0, centre_y = 0;  // where target lands, pixels
  double scale = 1;               // orthographic: pixels per world unit
  double distance = 1;            // perspective: eye to target, world units
  double focal = 1;               // perspective: pixels per unit at depth 1

  // The camera that shows all of `bounds` seen from `view` inside the picture
  // region [x0, x0 + width) × [y0, y0 + height) pixels, with a small margin.
  static Camera fit(const Box<double>& bounds, View view, Projection projection, double x0, double y0,
                    double width, double height);

  // Where p lands; nothing when it is behind or too close to a perspective eye.
  std::optional<Projected> project(const Vec3d& p) const;
};

// The unit frame of a view: forward, right, up.
void view_axes(View view, Vec3d& forward, Vec3d& right, Vec3d& up);

View parse_view(std::string_view name);              // "front" | "top" | "iso"; std::invalid_argument otherwise
Projection parse_projection(std::string_view name);  // "ortho" | "perspective"

}  // namespace swirl::render
