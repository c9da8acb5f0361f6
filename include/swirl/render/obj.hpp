// Surface meshes as Wavefront OBJ files (text), for Blender, MeshLab and the
// many tools that read OBJ but not PLY.
//
// Layout, one record a line:
//   # swirl fluid surface (marching tetrahedra of the colour field)
//   # time T                the frame's simulated time (%.17g)
//   # iso C                 the colour field's level
//   v x y z                 one per vertex, in vertex order
//   vn nx ny nz             one per vertex, the same order (the unit outward normal)
//   f a//a b//b c//c        one per triangle, counter-clockwise seen from outside,
//                           1-based; vertex a has normal a, so v and vn indices agree
// Floats are written in their shortest form that reads back to the same float
// (fmt's), so read_obj() gives back the exact mesh. No material (.mtl) and no
// texture coordinates. write_obj() writes with io::write_file_atomic, so a
// failure leaves no partial file. About 3 × the PLY's bytes (text).
#pragma once

#include <filesystem>
#include <string>

#include "swirl/render/surface_mesh.hpp"

namespace swirl::render {

// The text of the OBJ file of `mesh` at simulated time `time`.
std::string encode_obj(const SurfaceMesh& mesh, double time);

// Writes the OBJ file atomically. Throws io::IoError.
void write_obj(const std::filesystem::path& path, const SurfaceMesh& mesh, double time);

struct ObjFile {
  SurfaceMesh mesh;  // cell_size is not stored: 0
  double time = 0;
};

// Reads a file that write_obj() wrote (the records above; other comments are
// skipped). Throws io::IoError naming the file and the line for anything else:
// another record, a number that does not read, a face that is not a triangle,
// whose v and vn indices differ or name a vertex out of range, or as many
// normals as vertices missing.
ObjFile read_obj(const std::filesystem::path& path);

}  // namespace swirl::render
