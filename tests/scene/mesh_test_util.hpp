// Triangle meshes written as STL (ASCII, binary) and OBJ by the tests of the
// mesh obstacles (scene obstacle_mesh): a unit cube and the stepped block of
// examples/step_block.stl, by their corners and triangles.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/vec3.hpp"

namespace swirl::scene::test {

struct Mesh {
  std::vector<Vec3d> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

// [0, 1]³, two triangles per face.
inline Mesh unit_cube() {
  Mesh m;
  for (int k = 0; k < 8; ++k) m.vertices.push_back({double(k & 1), double((k >> 1) & 1), double((k >> 2) & 1)});
  // Faces as quads (a, b, c, d) counter-clockwise from outside, split along a–c.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

// A block with two steps (examples/step_block.stl at `unit` per millimetre):
// in x–z the L-shaped profile (0, 0), (240, 0), (240, 80), (120, 80), (120,
// 160), (0, 160), extruded from y = 0 to `width` (mm). Its cap is fanned from
// the inner corner (120, 80), so no vertex lies on another triangle's edge.
inline Mesh step_block(double unit = 1, double width = 200) {
  const double px[6] = {0, 240, 240, 120, 120, 0}, pz[6] = {0, 0, 80, 80, 160, 160};
  Mesh m;
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k < 6; ++k) m.vertices.push_back(Vec3d{px[k], side * width, pz[k]} * unit);
  // The profile A..F runs counter-clockwise in (x, z), whose normal x × z is
  // −y: the fan as it is faces out at y = 0, reversed at y = width.
  const int fan[4][2] = {{4, 5}, {5, 0}, {0, 1}, {1, 2}};  // (D, E, F), (D, F, A), (D, A, B), (D, B, C)
  for (const auto& f : fan) {
    m.triangles.push_back({3, f[0], f[1]});       // y = 0 side
    m.triangles.push_back({9, 6 + f[1], 6 + f[0]});  // y = width side
  }
  // The walls around the profile: quad (k, k+1) at y = 0 and y = width.
  for (int k = 0; k < 6; ++k) {
    const int a = k, b = (k + 1) % 6;
    m.triangles.push_back({a, 6 + b, b});  // y × (b − a) points out of the profile
    m.triangles.push_back({a, 6 + a, 6 + b});
  }
  return m;
}

inline Vec3d normal_of(const Mesh& m, const std::array<int, 3>& t) {
  const Vec3d a = m.vertices[std::size_t(t[0])], b = m.vertices[std::size_t(t[1])], c = m.vertices[std::size_t(t[2])];
  const Vec3d u = b - a, v = c - a;
  Vec3d n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
  return n * (1 / norm(n));
}

inline std::string ascii_stl(const Mesh& m) {
  std::string out = "solid swirl_test\n";
  for (const auto& t : m.triangles) {
    const Vec3d n = normal_of(m, t);
    out += fmt::format("  facet normal {} {} {}\n    outer loop\n", n.x, n.y, n.z);
    for (const int v : t) {
      const Vec3d& x = m.vertices[std::size_t(v)];
      out += fmt::format("      vertex {} {} {}\n", x.x, x.y, x.z);
    }
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid swirl_test\n";
}

inline std::string binary_stl(const Mesh& m) {
  std::string out(80, '\0');
  out.replace(0, 10, "swirl test");
  const auto put = [&](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
  const auto count = std::uint32_t(m.triangles.size());
  put(&count, 4);
  for (const auto& t : m.triangles) {
    const Vec3d n = normal_of(m, t);
    const float normal[3] = {float(n.x), float(n.y), float(n.z)};
    put(normal, 12);
    for (const int v : t) {
      const Vec3d& x = m.vertices[std::size_t(v)];
      const float p[3] = {float(x.x), float(x.y), float(x.z)};
      put(p, 12);
    }
    const std::uint16_t attributes = 0;
    put(&attributes, 2);
  }
  return out;
}

inline std::string obj(const Mesh& m) {
  std::string out = "# swirl test\n";
  for (const auto& x : m.vertices) out += fmt::format("v {} {} {}\n", x.x, x.y, x.z);
  for (const auto& t : m.triangles) out += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  return out;
}

}  // namespace swirl::scene::test
