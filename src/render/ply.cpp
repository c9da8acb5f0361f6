#include "swirl/render/ply.hpp"

#include <bit>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/read_file.hpp"

namespace swirl::render {
namespace {

static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big);

// Appends the 4 bytes of `v` in little-endian order.
template <class T>
void put(std::string& out, T v) {
  static_assert(sizeof(T) == 4);
  auto bits = std::bit_cast<std::uint32_t>(v);
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((bits >> (8 * b)) & 0xffu));
}

template <class T>
T get(const std::string& in, std::size_t at) {
  std::uint32_t bits = 0;
  for (int b = 3; b >= 0; --b) bits = (bits << 8) | static_cast<unsigned char>(in[at + static_cast<std::size_t>(b)]);
  return std::bit_cast<T>(bits);
}

constexpr std::string_view kVertexProperties =
    "property float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\n";
constexpr std::string_view kFaceProperty = "property list uchar uint vertex_indices\n";

}  // namespace

std::string encode_ply(const SurfaceMesh& mesh, double time) {
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment swirl fluid surface (marching tetrahedra of the colour field)\n"
      "comment time {:.17g}\ncomment iso {:.17g}\nelement vertex {}\n{}element face {}\n{}end_header\n",
      time, mesh.iso, mesh.vertices.size(), kVertexProperties, mesh.triangle_count(), kFaceProperty);
  out.reserve(out.size() + mesh.vertices.size() * 24 + mesh.triangle_count() * 13);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    for (int a = 0; a < 3; ++a) put(out, mesh.vertices[v][a]);
    for (int a = 0; a < 3; ++a) put(out, mesh.normals[v][a]);
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    out.push_back(3);
    for (std::size_t c = 0; c < 3; ++c) put(out, mesh.indices[3 * t + c]);
  }
  return out;
}

void write_ply(const std::filesystem::path& path, const SurfaceMesh& mesh, double time) {
  io::write_file_atomic(path, encode_ply(mesh, time));
}

PlyFile read_ply(const std::filesystem::path& path) {
  const std::string bytes = io::read_regular_file(path, std::uintmax_t{1} << 34);
  auto fail = [&](const std::string& why) { return io::IoError(path.string() + ": not a swirl surface PLY file: " + why); };
  const std::size_t end = bytes.find("end_header\n");
  if (bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0) != 0 || end == std::string::npos)
    throw fail("no binary little-endian PLY header");
  std::istringstream header(bytes.substr(0, end));
  std::string line;
  PlyFile file;
  std::size_t vertices = 0, faces = 0;
  bool seen_vertex = false, seen_face = false;
  try {
    while (std::getline(header, line)) {
      std::istringstream words(line);
      std::string w0, w1, w2;
      words >> w0 >> w1 >> w2;
      if (w0 == "comment" && w1 == "time") file.time = std::stod(w2);
      else if (w0 == "comment" && w1 == "iso") file.mesh.iso = std::stod(w2);
      else if (w0 == "element" && w1 == "vertex") vertices = std::stoull(w2), seen_vertex = true;
      else if (w0 == "element" && w1 == "face") faces = std::stoull(w2), seen_face = true;
    }
  } catch (const std::logic_error&) {
    throw fail("header line '" + line + "'");
  }
  if (!seen_vertex || !seen_face || bytes.find(std::string(kVertexProperties)) == std::string::npos ||
      bytes.find(std::string(kFaceProperty)) == std::string::npos)
    throw fail("not the vertex and face layout write_ply() writes");
  std::size_t at = end + std::string_view("end_header\n").size();
  if (vertices > bytes.size() / 24 || faces > bytes.size() / 13 || bytes.size() != at + vertices * 24 + faces * 13)
    throw fail(fmt::format("{} bytes of data for {} vertices and {} faces", bytes.size() - at, vertices, faces));
  file.mesh.vertices.resize(vertices);
  file.mesh.normals.resize(vertices);
  for (std::size_t v = 0; v < vertices; ++v, at += 24)
    for (int a = 0; a < 3; ++a) {
      file.mesh.vertices[v][a] = get<float>(bytes, at + 4 * static_cast<std::size_t>(a));
      file.mesh.normals[v][a] = get<float>(bytes, at + 12 + 4 * static_cast<std::size_t>(a));
    }
  file.mesh.indices.resize(3 * faces);
  for (std::size_t t = 0; t < faces; ++t, at += 13) {
    if (bytes[at] != 3) throw fail(fmt::format("face {} is not a triangle", t));
    for (std::size_t c = 0; c < 3; ++c) {
      const auto index = get<std::uint32_t>(bytes, at + 1 + 4 * c);
      if (index >= vertices) throw fail(fmt::format("face {} names vertex {} of {}", t, index, vertices));
      file.mesh.indices[3 * t + c] = index;
    }
  }
  return file;
}

}  // namespace swirl::render
