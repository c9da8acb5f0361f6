// Triangle meshes from STL (ASCII and binary) and Wavefront OBJ files, read
// through the Open Asset Import Library (Debian's libassimp-dev): the
// obstacles of a scene (scene obstacle_mesh).
//
// The file is read whole (io::read_regular_file, at most kMaxMeshBytes) and
// handed to Assimp from memory, so an OBJ's material library or any other file
// it names is never opened. Polygons are triangulated; lines and points are
// dropped. Vertices at exactly the same coordinates are merged into one, in
// the order of their first appearance (an STL repeats each vertex in every
// facet that uses it), so that triangles sharing an edge share its two vertex
// indices; a triangle left with two equal corners is dropped. Coordinates are
// Assimp's (single precision), widened to double.
//
// Refused with an IoError naming the file and the reason: a file that cannot
// be read, a file name that does not end in .stl or .obj, a file Assimp cannot
// parse (its message is quoted), a file without vertices, without triangles,
// or with a coordinate that is not finite (naming the vertex).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "swirl/core/vec3.hpp"
#include "swirl/io/read_file.hpp"

namespace swirl::io {

// The largest mesh file read: 1 GiB (a binary STL of 21 million triangles).
inline constexpr std::uintmax_t kMaxMeshBytes = 1024 * kMiB;

struct TriangleMesh {
  std::vector<Vec3d> vertices;                            // merged: no two equal
  std::vector<std::array<std::uint32_t, 3>> triangles;   // indices into vertices, three different ones each
};

// The triangles of an .stl or .obj file (by its extension, in any case).
TriangleMesh read_triangle_mesh(const std::filesystem::path& path);

}  // namespace swirl::io
