// Particles drawn as soft, shaded discs in depth order (painter's algorithm).
//
// Each particle becomes a disc of world radius `radius` (at least
// min_radius_px pixels) coloured by colormap((value − lo) / (hi − lo)); its
// opacity is `opacity` in the middle and falls to 0 at the rim, and it is
// shaded like a sphere (brighter in the middle) so overlapping particles read
// as a surface. A NaN value is drawn in style.solid instead (not a fluid). Discs are blended far to near; equal depths keep particle
// order, so the picture does not depend on anything but the input.
//
// Parallel and deterministic: the picture is cut into tiles of tile_size²
// pixels, particles are binned to the tiles they touch (in drawing order), and
// each tile blends its own pixels; a pixel sees the same operations in the same
// order as in draw_splats_reference(), the serial, untiled slow twin, so both
// give bit-identical images for any thread count.
#pragma once

#include <span>

#include "swirl/core/vec3.hpp"
#include "swirl/render/camera.hpp"
#include "swirl/render/colormap.hpp"
#include "swirl/render/image.hpp"

namespace swirl::render {

struct SplatStyle {
  ColorMap map = ColorMap::Viridis;
  double lo = 0, hi = 1;        // value range of the colour map (hi > lo, else everything gets t = 0)
  double radius = 0.01;         // world units
  double min_radius_px = 0.75;  // so far or tiny particles still show
  float opacity = 0.9f;         // at the disc's centre, in [0, 1]
  Color solid{0.62f, 0.62f, 0.66f};  // the colour of a NaN value: solids (obstacles' boundary particles)
  int tile_size = 32;           // pixels; any value ≥ 1 gives the same picture
};

// Draws the particles over `image`. values.size() == positions.size().
void draw_splats(Image& image, const Camera& camera, std::span<const Vec3d> positions,
                 std::span<const double> values, const SplatStyle& style);

// The slow twin: one particle after the other over the whole image, serially.
void draw_splats_reference(Image& image, const Camera& camera, std::span<const Vec3d> positions,
                           std::span<const double> values, const SplatStyle& style);

}  // namespace swirl::render
