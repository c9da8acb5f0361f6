// The fluid's surface as a triangle mesh: a smoothed colour field of the
// particles on a regular grid, and its iso-surface by marching tetrahedra.
//
// Colour field (the approach of splashsurf and of Akinci et al. 2012, in its
// simplest form): c(x) = Σ_j V_j W(|x − x_j|, R), with V_j the particle's
// volume (m_j/ρ0 for a fluid at rest density, or m_j/ρ_j) and W the poly6
// kernel W(r, R) = 315/(64π R³)·(1 − r²/R²)³ for r < R, whose integral is 1.
// Inside the fluid c ≈ 1 (the lattice sum of W·V), outside c = 0, and across
// a flat free surface c falls through ½ exactly where a continuous fluid
// would end: half a particle spacing beyond the outermost particles. So the
// surface is the level c = iso with iso = ½ by default. A curved surface
// sits a little inside (the kernel's variance over the radius of curvature):
// a sphere of radius 12 spacings, with R = 2 spacings, loses about 1 % of its
// volume (docs/surface.md, measured).
//
// Grid: nodes at origin + cell·(i, j, k), a dense grid bounded by the
// particles' bounds grown by R + 2 cells, so its outer two layers are 0 and
// the mesh is closed. When it would need more than max_nodes nodes, the cell
// is doubled until it fits (SurfaceMesh::cell_size says which was used).
//
// Mesh: every grid cube is cut into the six tetrahedra around its main
// diagonal (Kuhn's triangulation, which tiles space consistently), and each
// tetrahedron that the level crosses gives one or two triangles, with
// vertices on its edges by linear interpolation. Every tetrahedron edge is a
// grid node and one of the 7 steps {0,1}³ \ 0, so vertices are welded by that
// edge: the mesh is closed (every edge in exactly two triangles) and
// consistently oriented, counter-clockwise seen from outside (lower c). No
// table of cases is needed, so none is stored. Normals are −∇c (central
// differences), interpolated along the edge and normalised.
//
// Units: whatever the positions are in (m for SPH scenes); volumes in those
// units cubed. Parallel over z layers of the grid with swirl's thread pool:
// each layer writes only its own nodes, particles are added to a node in
// index order, vertices are numbered by node and step, triangles by cube and
// tetrahedron, so the mesh is bit-identical for any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "swirl/core/vec3.hpp"

namespace swirl::render {

struct SurfaceParams {
  double kernel_radius = 0;  // R, > 0: support radius of the smoothing kernel (length)
  double cell_size = 0;      // > 0: grid spacing of the colour field (length)
  double iso = 0.5;          // the level of the surface, in (0, 1)
  std::size_t max_nodes = std::size_t{1} << 24;  // grid nodes at most (4 bytes each, + 5 for the mesh pass)
};

// The usual parameters for particles of volume V = spacing³ (spacing = the
// fluid's lattice spacing, (m/ρ0)^(1/3)): R = radius·spacing, cell =
// cell·spacing. Defaults R = 2 spacings, cell = ½ spacing, iso = ½.
SurfaceParams surface_params_for_spacing(double spacing, double radius = 2.0, double cell = 0.5, double iso = 0.5);

// The colour field on its grid: value(i, j, k) at origin + cell·(i, j, k).
struct ColorField {
  Vec3d origin{};
  double cell = 0;
  int nx = 0, ny = 0, nz = 0;
  std::vector<float> value;  // x fastest, then y, then z
  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(ny) + static_cast<std::size_t>(j)) *
               static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
  }
  float at(int i, int j, int k) const { return value[index(i, j, k)]; }
};

struct SurfaceMesh {
  std::vector<Vec3<float>> vertices;  // positions
  std::vector<Vec3<float>> normals;   // unit outward normals, one per vertex
  std::vector<std::uint32_t> indices; // three per triangle, counter-clockwise from outside
  double cell_size = 0;               // the grid cell used (after any coarsening)
  double iso = 0.5;
  std::size_t triangle_count() const { return indices.size() / 3; }
};

// c on the grid. volumes holds one volume per particle, or a single one for
// all. Throws std::invalid_argument for bad parameters or sizes.
ColorField color_field(std::span<const Vec3d> positions, std::span<const double> volumes, const SurfaceParams& params);

// The level-`iso` surface of a field (marching tetrahedra, as above).
SurfaceMesh extract_surface(const ColorField& field, double iso);

// color_field, then extract_surface. No particles: an empty mesh.
SurfaceMesh reconstruct_surface(std::span<const Vec3d> positions, std::span<const double> volumes,
                                const SurfaceParams& params);

// The volume a closed, outward-oriented mesh encloses (divergence theorem:
// Σ a·(b × c)/6 over the triangles, in triangle order, in double).
double enclosed_volume(const SurfaceMesh& mesh);

}  // namespace swirl::render
