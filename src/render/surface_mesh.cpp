#include "swirl/render/surface_mesh.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::render {
namespace {

constexpr int kSlabLayers = 4;  // node layers per work item of the field pass

// The 7 steps from a node to the other nodes of its cube: step s (1..7) is
// (s & 1, s >> 1 & 1, s >> 2 & 1); a vertex on the edge (node, node + step s)
// is bit s − 1 of the node's mask.
Vec3d step_vector(unsigned s) { return {double(s & 1u), double((s >> 1) & 1u), double((s >> 2) & 1u)}; }

}  // namespace

SurfaceParams surface_params_for_spacing(double spacing, double radius, double cell, double iso) {
  SurfaceParams p;
  p.kernel_radius = radius * spacing;
  p.cell_size = cell * spacing;
  p.iso = iso;
  return p;
}

ColorField color_field(std::span<const Vec3d> positions, std::span<const double> volumes, const SurfaceParams& params) {
  const double R = params.kernel_radius;
  if (!(R > 0) || !std::isfinite(R)) throw std::invalid_argument("surface: the kernel radius must be positive");
  if (!(params.cell_size > 0) || !std::isfinite(params.cell_size))
    throw std::invalid_argument("surface: the grid cell must be positive");
  if (volumes.size() != positions.size() && volumes.size() != 1)
    throw std::invalid_argument("surface: one volume per particle, or one for all");
  ColorField f;
  if (positions.empty()) return f;

  Vec3d lo = positions.front(), hi = positions.front();
  for (const Vec3d& p : positions) {
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
      throw std::invalid_argument("surface: a particle position is not finite");
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  // Grow by R + 2 cells so that the two outer node layers see no particle;
  // coarsen (double the cell) until the grid fits.
  double cell = params.cell_size;
  std::array<std::size_t, 3> n{};
  for (;;) {
    std::size_t total = 1;
    for (int a = 0; a < 3; ++a) {
      const double extent = hi[a] - lo[a] + 2 * (R + 2 * cell);
      n[static_cast<std::size_t>(a)] = static_cast<std::size_t>(std::ceil(extent / cell)) + 1;
      total = total > std::numeric_limits<std::size_t>::max() / n[static_cast<std::size_t>(a)]
                  ? std::numeric_limits<std::size_t>::max()
                  : total * n[static_cast<std::size_t>(a)];
    }
    if (total <= std::max<std::size_t>(params.max_nodes, 64) && n[0] < (1u << 30) && n[1] < (1u << 30) && n[2] < (1u << 30))
      break;
    cell *= 2;
  }
  f.cell = cell;
  f.nx = static_cast<int>(n[0]);
  f.ny = static_cast<int>(n[1]);
  f.nz = static_cast<int>(n[2]);
  for (int a = 0; a < 3; ++a) f.origin[a] = lo[a] - (R + 2 * cell);
  f.value.assign(n[0] * n[1] * n[2], 0.0f);

  // Each particle's node range per axis (inclusive): nodes within R.
  struct Range { int lo, hi; };
  auto node_range = [&](double x, int axis, int count) {
    const double a = (x - R - f.origin[axis]) / cell, b = (x + R - f.origin[axis]) / cell;
    return Range{std::max(0, static_cast<int>(std::ceil(a))), std::min(count - 1, static_cast<int>(std::floor(b)))};
  };

  // Bin the particles to the slabs of kSlabLayers node layers their kernels
  // reach (CSR, in index order).
  const std::size_t slabs = (n[2] + kSlabLayers - 1) / kSlabLayers;
  std::vector<std::size_t> offsets(slabs + 1, 0);
  for (const Vec3d& p : positions) {
    const Range z = node_range(p.z, 2, f.nz);
    for (int s = z.lo / kSlabLayers; s <= z.hi / kSlabLayers; ++s) ++offsets[static_cast<std::size_t>(s) + 1];
  }
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::uint32_t> members(offsets.back());
  {
    std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const Range z = node_range(positions[i].z, 2, f.nz);
      for (int s = z.lo / kSlabLayers; s <= z.hi / kSlabLayers; ++s)
        members[fill[static_cast<std::size_t>(s)]++] = static_cast<std::uint32_t>(i);
    }
  }

  // Each slab adds its particles' kernels to its own nodes, particle by
  // particle in index order: the same sums in the same order for any threads.
  const double R2 = R * R, inv_R2 = 1.0 / R2;
  const double norm = 315.0 / (64.0 * std::numbers::pi * R * R * R);
  parallel::for_blocks("surface.field", slabs, 1, [&](std::size_t s, std::size_t, std::size_t) {
    const int k0 = static_cast<int>(s) * kSlabLayers, k1 = std::min(k0 + kSlabLayers, f.nz) - 1;
    for (std::size_t m = offsets[s]; m < offsets[s + 1]; ++m) {
      const std::uint32_t i = members[m];
      const Vec3d& p = positions[i];
      const double weight = norm * (volumes.size() == 1 ? volumes[0] : volumes[i]);
      const Range rx = node_range(p.x, 0, f.nx), ry = node_range(p.y, 1, f.ny), rz = node_range(p.z, 2, f.nz);
      for (int k = std::max(rz.lo, k0); k <= std::min(rz.hi, k1); ++k) {
        const double dz = f.origin.z + cell * k - p.z;
        for (int j = ry.lo; j <= ry.hi; ++j) {
          const double dy = f.origin.y + cell * j - p.y;
          const double r2_yz = dy * dy + dz * dz;
          if (r2_yz >= R2) continue;
          float* row = f.value.data() + f.index(0, j, k);
          for (int ii = rx.lo; ii <= rx.hi; ++ii) {
            const double dx = f.origin.x + cell * ii - p.x;
            const double r2 = dx * dx + r2_yz;
            if (r2 >= R2) continue;
            const double u = 1.0 - r2 * inv_R2;
            row[ii] += static_cast<float>(weight * u * u * u);
          }
        }
      }
    }
  });
  return f;
}

SurfaceMesh extract_surface(const ColorField& f, double iso) {
  if (!(iso > 0 && iso < 1)) throw std::invalid_argument("surface: the iso value must be in (0, 1)");
  SurfaceMesh mesh;
  mesh.cell_size = f.cell;
  mesh.iso = iso;
  if (f.nx < 2 || f.ny < 2 || f.nz < 2) return mesh;
  const auto level = static_cast<float>(iso);
  const std::size_t nodes = f.value.size();
  const auto nz = static_cast<std::size_t>(f.nz);
  const std::size_t layer = static_cast<std::size_t>(f.nx) * static_cast<std::size_t>(f.ny);
  auto inside = [&](std::size_t node) { return f.value[node] > level; };
  const std::array<std::size_t, 8> corner_offset = [&] {
    std::array<std::size_t, 8> o{};
    for (unsigned c = 0; c < 8; ++c)
      o[c] = (c & 1u) + ((c >> 1) & 1u) * static_cast<std::size_t>(f.nx) + ((c >> 2) & 1u) * layer;
    return o;
  }();

  // 1. Which edges from each node the level crosses (the mask), per z layer.
  std::vector<std::uint8_t> mask(nodes, 0);
  std::vector<std::uint32_t> layer_count(nz, 0);
  parallel::for_blocks("surface.edges", nz, 1, [&](std::size_t k, std::size_t, std::size_t) {
    std::uint32_t count = 0;
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) {
        const std::size_t node = f.index(i, j, static_cast<int>(k));
        const bool in = inside(node);
        std::uint8_t bits = 0;
        for (unsigned s = 1; s < 8; ++s) {
          const int di = int(s & 1u), dj = int((s >> 1) & 1u), dk = int((s >> 2) & 1u);
          if (i + di >= f.nx || j + dj >= f.ny || static_cast<int>(k) + dk >= f.nz) continue;
          if (inside(node + corner_offset[s]) != in) bits = static_cast<std::uint8_t>(bits | (1u << (s - 1)));
        }
        mask[node] = bits;
        count += static_cast<std::uint32_t>(std::popcount(bits));
      }
    layer_count[k] = count;
  });
  std::vector<std::uint64_t> layer_first(nz + 1, 0);
  for (std::size_t k = 0; k < nz; ++k) layer_first[k + 1] = layer_first[k] + layer_count[k];
  if (layer_first[nz] >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("surface: more than 2^32 vertices; use a coarser grid");

  // 2. Vertices, numbered by node then step: positions and normals.
  const std::size_t vertex_count = layer_first[nz];
  mesh.vertices.resize(vertex_count);
  mesh.normals.resize(vertex_count);
  std::vector<std::uint32_t> first_vertex(nodes, 0);
  auto gradient = [&](int i, int j, int k) {
    auto v = [&](int a, int b, int c) {
      return static_cast<double>(f.at(std::clamp(a, 0, f.nx - 1), std::clamp(b, 0, f.ny - 1), std::clamp(c, 0, f.nz - 1)));
    };
    return Vec3d{v(i + 1, j, k) - v(i - 1, j, k), v(i, j + 1, k) - v(i, j - 1, k), v(i, j, k + 1) - v(i, j, k - 1)};
  };
  parallel::for_blocks("surface.vertices", nz, 1, [&](std::size_t kk, std::size_t, std::size_t) {
    const int k = static_cast<int>(kk);
    auto next = static_cast<std::uint32_t>(layer_first[kk]);
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) {
        const std::size_t node = f.index(i, j, k);
        first_vertex[node] = next;
        const std::uint8_t bits = mask[node];
        if (bits == 0) continue;
        const Vec3d a{f.origin.x + f.cell * i, f.origin.y + f.cell * j, f.origin.z + f.cell * k};
        const double ca = f.value[node];
        const Vec3d ga = gradient(i, j, k);
        for (unsigned s = 1; s < 8; ++s) {
          if (!(bits & (1u << (s - 1)))) continue;
          const double cb = f.value[node + corner_offset[s]];
          const double t = std::clamp((iso - ca) / (cb - ca), 0.0, 1.0);
          const Vec3d d = step_vector(s);
          const Vec3d p = a + d * (t * f.cell);
          const Vec3d g = ga + (gradient(i + int(s & 1u), j + int((s >> 1) & 1u), k + int((s >> 2) & 1u)) - ga) * t;
          const double len = norm(g);
          // −∇c points out of the fluid; a flat field (never at a crossing in practice) falls back to the edge.
          const Vec3d nrm = len > 0 ? g * (-1.0 / len) : (ca > cb ? d : d * -1.0) * (1.0 / norm(d));
          mesh.vertices[next] = p.cast<float>();
          mesh.normals[next] = nrm.cast<float>();
          ++next;
        }
      }
  });
  auto vertex_of = [&](std::size_t node, unsigned s) {
    const unsigned below = mask[node] & ((1u << (s - 1)) - 1u);
    return first_vertex[node] + static_cast<std::uint32_t>(std::popcount(below));
  };

  // 3. Triangles, by cube (z layers in parallel, each into its own list) and
  // tetrahedron. Cube corners are numbered like steps (bit 0: +x, 1: +y, 2: +z);
  // the six tetrahedra are 0 → e_a → e_a + e_b → 7 for the permutations (a, b, c).
  static constexpr std::array<std::array<unsigned, 4>, 6> kTets{{
      {0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};
  std::vector<std::vector<std::uint32_t>> layer_indices(nz > 0 ? nz - 1 : 0);
  parallel::for_blocks("surface.triangles", nz - 1, 1, [&](std::size_t kk, std::size_t, std::size_t) {
    std::vector<std::uint32_t>& out = layer_indices[kk];
    const int k = static_cast<int>(kk);
    for (int j = 0; j + 1 < f.ny; ++j)
      for (int i = 0; i + 1 < f.nx; ++i) {
        const std::size_t base = f.index(i, j, k);
        std::array<bool, 8> in{};
        int count = 0;
        for (unsigned c = 0; c < 8; ++c) count += (in[c] = inside(base + corner_offset[c])) ? 1 : 0;
        if (count == 0 || count == 8) continue;
        for (const auto& tet : kTets) {
          // The vertex on the tetrahedron's edge between corners u and w (u's bits ⊂ w's).
          auto edge = [&](unsigned u, unsigned w) {
            if (u > w) std::swap(u, w);
            return vertex_of(base + corner_offset[u], u ^ w);
          };
          auto midpoint = [&](unsigned u, unsigned w) { return (step_vector(u) + step_vector(w)) * 0.5; };
          std::array<unsigned, 4> ins{}, outs{};
          int n_in = 0, n_out = 0;
          for (unsigned c : tet) {
            if (in[c]) ins[static_cast<std::size_t>(n_in++)] = c;
            else outs[static_cast<std::size_t>(n_out++)] = c;
          }
          if (n_in == 0 || n_in == 4) continue;
          Vec3d centre_in{}, centre_out{};
          for (int q = 0; q < n_in; ++q) centre_in += step_vector(ins[static_cast<std::size_t>(q)]);
          for (int q = 0; q < n_out; ++q) centre_out += step_vector(outs[static_cast<std::size_t>(q)]);
          const Vec3d outward = centre_out * (1.0 / n_out) - centre_in * (1.0 / n_in);
          // Emits the triangle of edges e0, e1, e2 (pairs of corners), turned
          // so that it faces outward: decided on the edges' midpoints, which
          // never coincide, so the orientation is exact and combinatorial.
          auto emit = [&](std::array<unsigned, 2> e0, std::array<unsigned, 2> e1, std::array<unsigned, 2> e2) {
            const Vec3d m0 = midpoint(e0[0], e0[1]), m1 = midpoint(e1[0], e1[1]), m2 = midpoint(e2[0], e2[1]);
            const bool flip = dot(cross(m1 - m0, m2 - m0), outward) < 0;
            out.push_back(edge(e0[0], e0[1]));
            out.push_back(edge((flip ? e2 : e1)[0], (flip ? e2 : e1)[1]));
            out.push_back(edge((flip ? e1 : e2)[0], (flip ? e1 : e2)[1]));
          };
          if (n_in == 1 || n_in == 3) {
            const unsigned apex = n_in == 1 ? ins[0] : outs[0];
            const std::array<unsigned, 4>& rest = n_in == 1 ? outs : ins;
            emit({apex, rest[0]}, {apex, rest[1]}, {apex, rest[2]});
          } else {
            const unsigned a = ins[0], b = ins[1], c = outs[0], d = outs[1];
            // The quad ac, ad, bd, bc, cut along ac–bd.
            emit({a, c}, {a, d}, {b, d});
            emit({a, c}, {b, d}, {b, c});
          }
        }
      }
  });
  std::size_t total = 0;
  for (const auto& l : layer_indices) total += l.size();
  mesh.indices.reserve(total);
  for (const auto& l : layer_indices) mesh.indices.insert(mesh.indices.end(), l.begin(), l.end());
  return mesh;
}

SurfaceMesh reconstruct_surface(std::span<const Vec3d> positions, std::span<const double> volumes,
                                const SurfaceParams& params) {
  if (!(params.iso > 0 && params.iso < 1)) throw std::invalid_argument("surface: the iso value must be in (0, 1)");
  const ColorField field = color_field(positions, volumes, params);
  SurfaceMesh mesh = extract_surface(field, params.iso);
  if (positions.empty()) mesh.cell_size = params.cell_size;
  return mesh;
}

double enclosed_volume(const SurfaceMesh& mesh) {
  double six_v = 0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const Vec3d a = mesh.vertices[mesh.indices[t]].cast<double>(), b = mesh.vertices[mesh.indices[t + 1]].cast<double>(),
                c = mesh.vertices[mesh.indices[t + 2]].cast<double>();
    six_v += dot(a, cross(b, c));
  }
  return six_v / 6.0;
}

}  // namespace swirl::render
