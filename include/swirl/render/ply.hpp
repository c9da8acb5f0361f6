// Surface meshes as PLY files (binary little-endian), for Blender and ParaView.
//
// Layout: a header with `comment time T` (the frame's simulated time) and
// `comment iso C` lines, `element vertex N` with float x, y, z, nx, ny, nz,
// and `element face M` with `property list uchar uint vertex_indices`
// (three per face, counter-clockwise seen from outside). write_ply() writes it
// with io::write_file_atomic, so a failure leaves no partial file; read_ply()
// reads back exactly that layout (for checks and for the run's series).
#pragma once

#include <filesystem>
#include <string>

#include "swirl/render/surface_mesh.hpp"

namespace swirl::render {

// The bytes of the PLY file of `mesh` at simulated time `time`.
std::string encode_ply(const SurfaceMesh& mesh, double time);

// Writes the PLY file atomically. Throws io::IoError.
void write_ply(const std::filesystem::path& path, const SurfaceMesh& mesh, double time);

struct PlyFile {
  SurfaceMesh mesh;  // cell_size is not stored: 0
  double time = 0;
};

// Reads a file that write_ply() wrote. Throws io::IoError naming the file for
// anything else (another layout, a truncated file, an index out of range).
PlyFile read_ply(const std::filesystem::path& path);

}  // namespace swirl::render
