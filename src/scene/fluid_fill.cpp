#include "swirl/scene/fluid_fill.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include <fmt/format.h>

#include "sources.hpp"
#include "swirl/scene/mesh_sampling.hpp"

namespace swirl::scene {
namespace {

// The mesh placement of an obstacle_mesh, so that both kinds place a file alike.
ObstacleSource as_obstacle(const FluidFillSource& fill) {
  ObstacleSource o;
  o.shape = ObstacleSource::Shape::Mesh;
  o.mesh = fill.mesh;
  o.scale = fill.scale;
  o.rotate_deg = fill.rotate_deg;
  o.translate = fill.translate;
  return o;
}

LatticeSource as_lattice(const FluidFillSource& fill) {
  LatticeSource l;
  l.region = fill_bounds(fill);
  l.spacing = fill.spacing;
  return l;
}

// a + b·c rounded twice, as the fluid_block's points (sources.cpp): no fused multiply-add.
double mul_add(double a, double b, double c) {
  const double bc = b * c;
  return a + bc;
}

}  // namespace

std::vector<Vec3d> placed_fill_vertices(const FluidFillSource& fill) { return placed_vertices(as_obstacle(fill)); }

Box<double> fill_bounds(const FluidFillSource& fill) {
  if (fill.shape == FluidFillSource::Shape::Sphere) {
    const Vec3d r{fill.radius, fill.radius, fill.radius};
    return {fill.center - r, fill.center + r};
  }
  const std::vector<Vec3d> x = placed_fill_vertices(fill);
  if (x.empty()) return {};
  Vec3d lo = x.front(), hi = x.front();
  for (const Vec3d& v : x)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
  return {lo, hi};
}

std::uint64_t fill_lattice_bound(const FluidFillSource& fill) {
  if (fill.shape == FluidFillSource::Shape::Mesh && !fill.mesh) return 0;
  const auto n = detail::lattice_counts(as_lattice(fill));
  return detail::mul_sat(detail::mul_sat(n[0], n[1]), n[2]);
}

std::string mesh_closure_problem(const io::TriangleMesh& mesh) {
  // Each undirected edge: how often it is run along from its lower vertex to
  // the higher, and the other way.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<std::uint32_t, 2>> uses;
  for (const auto& t : mesh.triangles)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      auto& u = uses[{std::min(a, b), std::max(a, b)}];
      ++u[a < b ? 0 : 1];
    }
  const auto at = [&](std::uint32_t v) {
    const Vec3d& p = mesh.vertices[v];
    return fmt::format("vertex {} ({}, {}, {})", v, p.x, p.y, p.z);
  };
  for (const auto& [edge, u] : uses) {
    const std::uint32_t total = u[0] + u[1];
    if (total != 2)
      return fmt::format("the mesh is not closed: the edge from {} to {} belongs to {} triangle{} (a closed surface "
                         "has every edge in exactly two)",
                         at(edge.first), at(edge.second), total, total == 1 ? "" : "s");
    if (u[0] != 1)
      return fmt::format("the mesh is not consistently oriented: the two triangles at the edge from {} to {} run "
                         "along it the same way (one of them faces the other way)",
                         at(edge.first), at(edge.second));
  }
  return {};
}

double winding_number(const std::vector<Vec3d>& x, const io::TriangleMesh& mesh, const Vec3d& p) {
  double sum = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3d a = x[t[0]] - p, b = x[t[1]] - p, c = x[t[2]] - p;
    const double la = norm(a), lb = norm(b), lc = norm(c);
    const double det = dot(a, cross(b, c));
    const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    sum += 2 * std::atan2(det, den);  // the solid angle the triangle subtends at p
  }
  return sum / (4 * std::numbers::pi);
}

std::vector<Vec3d> fill_points(const FluidFillSource& fill) {
  const std::uint64_t bound = fill_lattice_bound(fill);
  std::vector<Vec3d> out;
  if (bound == 0 || bound > detail::kMaxParticles || !(fill.spacing > 0)) return out;
  const bool sphere = fill.shape == FluidFillSource::Shape::Sphere;
  if (!sphere && (!fill.mesh || !mesh_indices_valid(*fill.mesh))) return out;
  if (!sphere && detail::mul_sat(bound, fill.mesh->triangles.size()) > kMaxFillWork) return out;
  const std::vector<Vec3d> x = sphere ? std::vector<Vec3d>{} : placed_fill_vertices(fill);
  const Box<double> b = fill_bounds(fill);
  const auto n = detail::lattice_counts(as_lattice(fill));
  const double r2 = fill.radius * fill.radius;
  for (std::uint64_t k = 0; k < n[2]; ++k)
    for (std::uint64_t j = 0; j < n[1]; ++j)
      for (std::uint64_t i = 0; i < n[0]; ++i) {
        const std::uint64_t index[3] = {i, j, k};
        Vec3d p;
        for (int axis = 0; axis < 3; ++axis)
          p[axis] = mul_add(b.lo[axis], fill.spacing, static_cast<double>(index[axis]) + 0.5);
        const bool inside = sphere ? dot(p - fill.center, p - fill.center) < r2
                                   : std::abs(winding_number(x, *fill.mesh, p)) >= 0.5;
        if (inside) out.push_back(p);
      }
  return out;
}

}  // namespace swirl::scene
