// The particles of a fluid fill (FluidFillSource, kinds "fluid_sphere" and
// "fluid_mesh"): the fluid_block's lattice over the shape's bounding box, the
// points inside the shape kept, in the lattice's order (x fastest, then y, z).
//
// Inside a mesh means a generalised winding number of at least ½ in magnitude
// (Jacobson et al. 2013): the sum over the triangles of the solid angle each
// subtends at the point (Van Oosterom & Strackee's formula), over 4π. For a
// closed, consistently oriented mesh it is ±1 inside and 0 outside, with no
// special cases where a ray would graze an edge or a vertex (a lattice point
// and a mesh built on the same grid often line up exactly); either orientation
// (normals out or in) gives the same points. Every step is serial and in
// double, so the points are the same bits on every run and for any thread
// count. The cost is one solid angle per lattice point of the bounding box
// and triangle: kMaxFillWork bounds it.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "swirl/core/box.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/io/mesh_file.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// The most (bounding-box lattice points × triangles) a fluid_mesh may cost:
// 2^34, about half a minute of solid angles on one core.
inline constexpr std::uint64_t kMaxFillWork = std::uint64_t{1} << 34;

// The box whose lattice the fill keeps the inside points of: a sphere's
// [center − radius, center + radius], a mesh's placed vertices' bounds (an
// empty box without a mesh).
Box<double> fill_bounds(const FluidFillSource& fill);

// The mesh's vertices as placed (scale, rotate_deg, translate), as an
// obstacle_mesh's (placed_vertices(), scene/mesh_sampling.hpp).
std::vector<Vec3d> placed_fill_vertices(const FluidFillSource& fill);

// Lattice points of fill_bounds(), saturating (the bound validation checks
// before anything is enumerated).
std::uint64_t fill_lattice_bound(const FluidFillSource& fill);

// Why the mesh is not a closed, consistently oriented surface ("" when it
// is): an edge not shared by exactly two triangles, or shared by two that run
// along it the same way (one of them faces the other way).
std::string mesh_closure_problem(const io::TriangleMesh& mesh);

// The generalised winding number of the triangles (vertices x) at p.
double winding_number(const std::vector<Vec3d>& x, const io::TriangleMesh& mesh, const Vec3d& p);

// The fill's particles' positions; empty when the bound exceeds 2^31 points,
// or a mesh's cost exceeds kMaxFillWork (validation refuses those first).
std::vector<Vec3d> fill_points(const FluidFillSource& fill);

}  // namespace swirl::scene
