// Projected (surface) density of a particle system, for gravity runs: the mass
// per unit picture area, Σ (mass / length²), shown on a log scale so that cores,
// tails and halos are visible at once.
//
// Each particle's mass is spread over the pixels within a radius R of its
// projected position with weights (1 − d²/R²)², normalised so the particle's
// whole mass lands on the picture grid (pixels outside the picture lose
// theirs), and divided by one pixel's world area at the particle's depth.
// R is fixed, or adaptive like an SPH smoothing length: wide enough to hold
// about `neighbours` particles of the picture plane where they are sparse
// (counted on a grid of 8-pixel cells), so halos and tails read as smooth
// structure rather than single dots, and never below min_px.
// Masses are added in particle order per pixel: tiled and parallel, yet
// bit-identical to surface_density_reference() for any thread count.
#pragma once

#include <span>
#include <vector>

#include "swirl/core/vec3.hpp"
#include "swirl/render/camera.hpp"
#include "swirl/render/colormap.hpp"
#include "swirl/render/image.hpp"

namespace swirl::render {

struct DensityMap {
  int width = 0, height = 0;
  std::vector<double> sigma;  // row by row from the top, mass / length²
  double at(int x, int y) const { return sigma[static_cast<std::size_t>(y) * width + x]; }
};

struct DensityKernel {
  double min_px = 1.5;    // kernel radius, pixels, ≥ 0.75 (the fixed radius when neighbours = 0)
  double neighbours = 0;  // > 0: adaptive radius holding about this many particles
  double max_px = 24;     // adaptive radii stop here
};

// Σ on a width × height grid; masses.size() == positions.size().
DensityMap surface_density(const Camera& camera, int width, int height, std::span<const Vec3d> positions,
                           std::span<const double> masses, const DensityKernel& kernel = {}, int tile_size = 32);

// The slow twin: one particle after the other, serially.
DensityMap surface_density_reference(const Camera& camera, int width, int height,
                                     std::span<const Vec3d> positions, std::span<const double> masses,
                                     const DensityKernel& kernel = {});

// Paints log10 Σ with `map` over [log_lo, log_hi] onto `image` (same size);
// pixels with Σ = 0 get the map's colour at 0.
void draw_log_density(Image& image, const DensityMap& density, ColorMap map, double log_lo, double log_hi);

}  // namespace swirl::render
