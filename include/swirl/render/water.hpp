// A surface mesh drawn as water: z-buffered triangles, shaded per pixel.
//
// The material: a deep blue body lit by one light fixed to the camera (from
// above, a little left and in front: Lambert, 35 % ambient), a Fresnel term
// (Schlick, F0 = 0.02, the value of water) that blends towards a pale sky
// colour at grazing angles, so the outline reads as a rim, and a Blinn–Phong
// highlight. Normals are the mesh's vertex normals, interpolated.
//
// Parallel and deterministic: the picture is cut into tiles, triangles are
// binned to the tiles they touch in index order, and each tile keeps its own
// depth buffer; a pixel takes the nearest triangle, the first one in index
// order on a tie. So every tile size and thread count gives the same picture.
#pragma once

#include "swirl/render/camera.hpp"
#include "swirl/render/image.hpp"
#include "swirl/render/surface_mesh.hpp"

namespace swirl::render {

struct WaterStyle {
  Color deep{0.02f, 0.20f, 0.40f};    // the body colour, lit
  Color sky{0.72f, 0.86f, 0.96f};     // what grazing angles reflect
  float ambient = 0.35f;              // of the body colour, unlit
  float fresnel_f0 = 0.02f;           // reflectance seen head-on
  float specular = 0.7f;              // highlight strength
  float shininess = 80.0f;            // Blinn–Phong exponent
  int tile_size = 32;                 // pixels; any value ≥ 1 gives the same picture
};

// Draws `mesh` over `image` (pixels it does not cover keep their colour).
void draw_water(Image& image, const Camera& camera, const SurfaceMesh& mesh, const WaterStyle& style = {});

}  // namespace swirl::render
