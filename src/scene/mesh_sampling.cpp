#include "swirl/scene/mesh_sampling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <utility>

#include "sources.hpp"

namespace swirl::scene {
namespace {

// a + (b − a)·(k/n), rounded step by step (separate statements, so that no
// compiler fuses a multiply-add that would round differently on some machines).
Vec3d between(const Vec3d& a, const Vec3d& b, std::uint64_t k, std::uint64_t n) {
  const double t = static_cast<double>(k) / static_cast<double>(n);
  Vec3d out;
  for (int axis = 0; axis < 3; ++axis) {
    const double d = b[axis] - a[axis];
    const double step = d * t;
    out[axis] = a[axis] + step;
  }
  return out;
}

// Intervals of at most `spacing` along `length`: ceil(length/spacing), the
// ratio shaved by 1e-12 of itself so that 0.3/0.1 is 3; at least 1. Huge
// ratios are capped (the caller's bound refuses them before they matter).
std::uint64_t intervals(double length, double spacing) {
  const double r = length / spacing;
  if (!(r > 0)) return 1;
  if (!(r < 0x1p40)) return std::uint64_t{1} << 40;
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(r - r * 1e-12)));
}

using Edge = std::pair<std::uint32_t, std::uint32_t>;  // (lower index, higher)

// The mesh's unique edges, in the order the triangles first name them.
std::vector<Edge> unique_edges(const io::TriangleMesh& mesh) {
  std::map<Edge, bool> seen;
  std::vector<Edge> edges;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
      const Edge e{std::min(a, b), std::max(a, b)};
      if (seen.emplace(e, true).second) edges.push_back(e);
    }
  return edges;
}

// A cheap upper bound of the count: V + Σ_edges L/s + Σ_triangles (2A/s² + L_base/s + 1).
double count_bound(const std::vector<Vec3d>& x, const io::TriangleMesh& mesh, const std::vector<Edge>& edges,
                   double s) {
  double bound = double(x.size());
  for (const auto& [a, b] : edges) bound += norm(x[b] - x[a]) / s + 1;
  for (const auto& t : mesh.triangles) {
    const Vec3d &p = x[t[0]], &q = x[t[1]], &r = x[t[2]];
    const double longest = std::max({norm(q - p), norm(r - q), norm(p - r)});
    bound += norm(cross(q - p, r - p)) / (s * s) + longest / s + 2;
  }
  return bound;
}

// Calls emit(point) for every point of the scheme (mesh_sampling.hpp), in order.
template <class Emit>
void sample(const std::vector<Vec3d>& x, const io::TriangleMesh& mesh, const std::vector<Edge>& edges, double s,
            Emit&& emit) {
  for (const Vec3d& v : x) emit(v);
  for (const auto& [a, b] : edges) {
    const std::uint64_t n = intervals(norm(x[b] - x[a]), s);
    for (std::uint64_t k = 1; k < n; ++k) emit(between(x[a], x[b], k, n));
  }
  for (const auto& t : mesh.triangles) {
    // The base: the longest edge (the first of equal ones), from p to q; r the apex.
    std::array<double, 3> length{};
    for (int k = 0; k < 3; ++k) length[std::size_t(k)] = norm(x[t[std::size_t((k + 1) % 3)]] - x[t[std::size_t(k)]]);
    int base = 0;
    for (int k = 1; k < 3; ++k)
      if (length[std::size_t(k)] > length[std::size_t(base)]) base = k;
    const Vec3d& p = x[t[std::size_t(base)]];
    const Vec3d& q = x[t[std::size_t((base + 1) % 3)]];
    const Vec3d& r = x[t[std::size_t((base + 2) % 3)]];
    const double base_length = length[std::size_t(base)];
    if (!(base_length > 0)) continue;
    const double height = norm(cross(q - p, r - p)) / base_length;
    const std::uint64_t rows = intervals(height, s);
    for (std::uint64_t k = 1; k < rows; ++k) {
      const Vec3d u = between(p, r, k, rows), v = between(q, r, k, rows);
      const double row_length = base_length * (static_cast<double>(rows - k) / static_cast<double>(rows));
      const std::uint64_t n = intervals(row_length, s);
      for (std::uint64_t j = 1; j < n; ++j) emit(between(u, v, j, n));
    }
  }
}

}  // namespace

bool mesh_indices_valid(const io::TriangleMesh& mesh) {
  const std::size_t n = mesh.vertices.size();
  return std::all_of(mesh.triangles.begin(), mesh.triangles.end(), [&](const std::array<std::uint32_t, 3>& t) {
    return t[0] < n && t[1] < n && t[2] < n && t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
  });
}

std::vector<Vec3d> placed_vertices(const ObstacleSource& o) {
  if (!o.mesh) return {};
  std::vector<Vec3d> out = o.mesh->vertices;
  const double deg = std::numbers::pi / 180;
  // Rotations about x, y, z in turn; an angle of 0 is skipped, so that an
  // unrotated mesh keeps its coordinates bit for bit.
  const auto rotate = [&](int axis, double degrees) {
    if (degrees == 0) return;
    double c = std::cos(degrees * deg), sn = std::sin(degrees * deg);
    // Quarter turns exactly (cos 180° would otherwise leave 1.2e-16 in sin,
    // and a face on the box's wall a hair outside it).
    if (const double quarters = degrees / 90; quarters == std::round(quarters) && std::abs(quarters) < 0x1p52) {
      const auto q = static_cast<std::int64_t>(quarters) % 4;
      constexpr double cs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
      c = cs[(q + 4) % 4][0];
      sn = cs[(q + 4) % 4][1];
    }
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    for (Vec3d& v : out) {
      const double a = v[i], b = v[j];
      const double ac = a * c, bs = b * sn, as = a * sn, bc = b * c;
      v[i] = ac - bs;
      v[j] = as + bc;
    }
  };
  if (o.scale != 1)
    for (Vec3d& v : out) v = v * o.scale;
  for (int axis = 0; axis < 3; ++axis) rotate(axis, o.rotate_deg[axis]);
  for (Vec3d& v : out) v = detail::moved(v, o.translate);
  return out;
}

std::uint64_t mesh_point_count(const ObstacleSource& o) {
  if (!o.mesh || !(o.spacing > 0) || !mesh_indices_valid(*o.mesh)) return 0;
  const std::vector<Vec3d> x = placed_vertices(o);
  const std::vector<Edge> edges = unique_edges(*o.mesh);
  const double bound = count_bound(x, *o.mesh, edges, o.spacing);
  if (!(bound <= double(16 * kMaxMeshParticles)))
    return bound < 0x1p63 ? static_cast<std::uint64_t>(bound) : detail::kSaturated;
  std::uint64_t count = 0;
  sample(x, *o.mesh, edges, o.spacing, [&](const Vec3d&) { ++count; });
  return count;
}

std::vector<Vec3d> mesh_points(const ObstacleSource& o) {
  const std::uint64_t count = mesh_point_count(o);
  if (count == 0 || count > kMaxMeshParticles) return {};
  const std::vector<Vec3d> x = placed_vertices(o);
  std::vector<Vec3d> out;
  out.reserve(static_cast<std::size_t>(count));
  sample(x, *o.mesh, unique_edges(*o.mesh), o.spacing, [&](const Vec3d& p) { out.push_back(p); });
  return out;
}

}  // namespace swirl::scene
