#include "swirl/io/mesh_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <tuple>

#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>  // AI_MEMORYIO_MAGIC_FILENAME
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

namespace swirl::io {
namespace {

// The file system Assimp sees beside the file handed to it from memory: empty.
// (Its default would open what the file names, an OBJ's material library,
// relative to the working directory.)
class NoFiles final : public Assimp::IOSystem {
 public:
  bool Exists(const char*) const override { return false; }
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char*, const char*) override { return nullptr; }
  void Close(Assimp::IOStream*) override {}
};

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

}  // namespace

TriangleMesh read_triangle_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string extension = lower(path.extension().string());
  if (extension != ".stl" && extension != ".obj")
    throw IoError(fmt::format("{}: not a mesh swirl reads: the name must end in .stl (ASCII or binary STL) or .obj "
                              "(Wavefront OBJ)",
                              name));
  const std::string bytes = read_regular_file(path, kMaxMeshBytes);
  if (bytes.empty()) throw IoError(fmt::format("{}: the file is empty", name));

  Assimp::Importer importer;
  importer.SetIOHandler(new NoFiles);  // owned by the importer
  // Only the triangulation of polygons: no smoothing, no merging of Assimp's
  // own (which compares normals too, and so would not merge an STL's corners).
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_Triangulate,
                                                     extension.c_str() + 1);
  if (!scene) {
    // Assimp names a file read from memory by a placeholder; name ours.
    std::string why = importer.GetErrorString();
    const std::string placeholder = std::string(AI_MEMORYIO_MAGIC_FILENAME) + "." + (extension.c_str() + 1);
    for (auto at = why.find(placeholder); at != std::string::npos; at = why.find(placeholder, at + name.size()))
      why.replace(at, placeholder.size(), name);
    throw IoError(fmt::format("{}: not a valid {} file (Assimp: {})", name, extension == ".stl" ? "STL" : "OBJ", why));
  }

  TriangleMesh mesh;
  // Merged vertices by their exact coordinates (−0 and +0 are one), in the order first seen.
  std::map<std::tuple<double, double, double>, std::uint32_t> index;
  std::size_t read_vertices = 0, other_faces = 0, dropped = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    read_vertices += part->mNumVertices;
    std::vector<std::uint32_t> merged(part->mNumVertices);
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& a = part->mVertices[v];
      const Vec3d x{double(a.x), double(a.y), double(a.z)};
      if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
        throw IoError(fmt::format("{}: vertex {} of mesh {} is ({}, {}, {}): coordinates must be finite", name, v, m,
                                  x.x, x.y, x.z));
      const auto [it, added] = index.try_emplace({x.x, x.y, x.z}, std::uint32_t(mesh.vertices.size()));
      if (added) mesh.vertices.push_back(x);
      merged[v] = it->second;
    }
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) {
        ++other_faces;
        continue;
      }
      std::array<std::uint32_t, 3> t{};
      bool valid = true;
      for (int k = 0; k < 3; ++k) {
        const unsigned v = face.mIndices[k];
        valid = valid && v < part->mNumVertices;
        t[std::size_t(k)] = valid ? merged[v] : 0;
      }
      if (!valid) throw IoError(fmt::format("{}: face {} of mesh {} names a vertex it does not have", name, f, m));
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
        ++dropped;
        continue;
      }
      mesh.triangles.push_back(t);
    }
  }
  if (read_vertices == 0) throw IoError(fmt::format("{}: the mesh is empty (no vertices)", name));
  if (mesh.triangles.empty())
    throw IoError(fmt::format("{}: the mesh has no triangles ({} vertices; {} faces of lines or points, {} triangles "
                              "with two corners at the same point)",
                              name, read_vertices, other_faces, dropped));
  // Keep only the vertices the triangles use (a file may list loose points).
  std::vector<std::uint32_t> used(mesh.vertices.size(), UINT32_MAX);
  std::vector<Vec3d> vertices;
  for (auto& t : mesh.triangles)
    for (auto& v : t) {
      if (used[v] == UINT32_MAX) {
        used[v] = std::uint32_t(vertices.size());
        vertices.push_back(mesh.vertices[v]);
      }
      v = used[v];
    }
  mesh.vertices = std::move(vertices);
  return mesh;
}

}  // namespace swirl::io
