// The boundary particles of a triangle mesh obstacle (kind = "obstacle_mesh"):
// its surface sampled evenly at a spacing s, in a fixed order.
//
// The scheme (deterministic: serial, double precision, the same bits on every
// run and for any thread count):
//   1. every vertex of the mesh, once, in the mesh's vertex order;
//   2. every edge, once however many triangles share it (in the order of
//      first appearance), at n = ceil(L/s) equal intervals, its n − 1 inner
//      points, from its lower-numbered vertex to the other;
//   3. every triangle's inside, in rows parallel to its longest edge (the
//      base; the first of equal ones): the height H over the base in m =
//      ceil(H/s) equal steps, and on row k (0 < k < m, at k/m of the way to
//      the apex) the segment between the two other edges at q = ceil(len/s)
//      equal intervals, its q − 1 inner points.
// Every step is at most s (ceil with a relative tolerance of 1e-12, so that
// 0.3/0.1 counts as 3), so sharp edges and corners are sampled exactly on
// them, no point is made twice along a shared edge, and every surface point
// lies within about s of a sample (measured: within 0.75 s on a cube and a
// wedge, tests/scene/mesh_obstacle_test.cpp). Rows near an edge may come
// closer to that edge's points than s; the boundary's volume weights ψ
// (docs/sph.md) make up for the local density.
#pragma once

#include <cstdint>
#include <vector>

#include "swirl/core/vec3.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// The most boundary particles one mesh obstacle may make: 2^24 (16.8 million,
// 400 MB of positions while sampled; at the fluid's spacing, a mesh surface
// of 16.8 million s², 4000 × 4000 spacings).
inline constexpr std::uint64_t kMaxMeshParticles = std::uint64_t{1} << 24;

// True when every triangle names three different vertices the mesh has (as
// io::read_triangle_mesh() makes them; a mesh built in code may not).
bool mesh_indices_valid(const io::TriangleMesh& mesh);

// The mesh's vertices where the scene places them: R·(scale·x) + translate,
// R the rotation by rotate_deg about x, then y, then z. Empty without a mesh.
std::vector<Vec3d> placed_vertices(const ObstacleSource& mesh);

// The number of points mesh_points() makes at the source's spacing, exact; or,
// when a cheap upper bound (about twice the count) exceeds 16·kMaxMeshParticles, that bound
// (saturating at UINT64_MAX; then > kMaxMeshParticles either way). 0 without
// a mesh, with invalid indices, or without a spacing.
std::uint64_t mesh_point_count(const ObstacleSource& mesh);

// The points, in the scheme's order; empty when there would be more than
// kMaxMeshParticles (validation refuses such a scene first).
std::vector<Vec3d> mesh_points(const ObstacleSource& mesh);

}  // namespace swirl::scene
