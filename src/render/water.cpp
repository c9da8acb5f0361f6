#include "swirl/render/water.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <vector>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::render {
namespace {

constexpr std::size_t kProjectBlock = 8192;

struct ScreenVertex {
  double x = 0, y = 0, depth = 0;
  bool ok = false;
};

// A triangle on the picture: its pixel rectangle (inclusive, clipped).
struct Footprint {
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
};

Vec3d unit(const Vec3d& v) {
  const double n = norm(v);
  return n > 0 ? v * (1.0 / n) : v;
}

}  // namespace

void draw_water(Image& image, const Camera& camera, const SurfaceMesh& mesh, const WaterStyle& style) {
  if (style.tile_size < 1) throw std::invalid_argument("draw_water: tile size must be at least 1");
  const int W = image.width(), H = image.height();
  std::vector<ScreenVertex> sv(mesh.vertices.size());
  parallel::for_blocks("water.project", sv.size(), kProjectBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t v = begin; v < end; ++v) {
      const auto p = camera.project(mesh.vertices[v].cast<double>());
      if (p && std::isfinite(p->x) && std::isfinite(p->y)) sv[v] = {p->x, p->y, p->depth, true};
    }
  });
  const std::size_t triangles = mesh.triangle_count();
  std::vector<Footprint> foot(triangles);
  parallel::for_blocks("water.footprints", triangles, kProjectBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t t = begin; t < end; ++t) {
      const ScreenVertex &a = sv[mesh.indices[3 * t]], &b = sv[mesh.indices[3 * t + 1]], &c = sv[mesh.indices[3 * t + 2]];
      if (!a.ok || !b.ok || !c.ok) continue;
      const double fx0 = std::floor(std::min({a.x, b.x, c.x}) - 0.5), fx1 = std::ceil(std::max({a.x, b.x, c.x}) - 0.5);
      const double fy0 = std::floor(std::min({a.y, b.y, c.y}) - 0.5), fy1 = std::ceil(std::max({a.y, b.y, c.y}) - 0.5);
      if (fx1 < 0 || fy1 < 0 || fx0 >= W || fy0 >= H) continue;
      foot[t] = {static_cast<int>(std::max(fx0, 0.0)), static_cast<int>(std::min(fx1, W - 1.0)),
                 static_cast<int>(std::max(fy0, 0.0)), static_cast<int>(std::min(fy1, H - 1.0))};
    }
  });

  // Bin the triangles to tiles, in index order (CSR).
  const int tile = style.tile_size;
  const int tiles_x = (W + tile - 1) / tile, tiles_y = (H + tile - 1) / tile;
  const auto tiles = static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y);
  std::vector<std::size_t> offsets(tiles + 1, 0);
  auto for_each_tile = [&](const Footprint& f, auto&& fn) {
    if (f.x0 > f.x1 || f.y0 > f.y1) return;
    for (int ty = f.y0 / tile; ty <= f.y1 / tile; ++ty)
      for (int tx = f.x0 / tile; tx <= f.x1 / tile; ++tx) fn(static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x) + static_cast<std::size_t>(tx));
  };
  for (const Footprint& f : foot) for_each_tile(f, [&](std::size_t t) { ++offsets[t + 1]; });
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::uint32_t> members(offsets.back());
  {
    std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t t = 0; t < triangles; ++t)
      for_each_tile(foot[t], [&](std::size_t k) { members[fill[k]++] = static_cast<std::uint32_t>(t); });
  }

  // Lighting in the camera's frame: the light from above, left and in front.
  const Vec3d light = unit(camera.up * 0.75 - camera.right * 0.35 - camera.forward * 0.55);
  const Vec3d eye = camera.target - camera.forward * camera.distance;
  const bool perspective = camera.projection == Projection::Perspective;

  parallel::for_blocks("water.tiles", tiles, 1, [&](std::size_t t, std::size_t, std::size_t) {
    const int tx0 = static_cast<int>(t % static_cast<std::size_t>(tiles_x)) * tile;
    const int ty0 = static_cast<int>(t / static_cast<std::size_t>(tiles_x)) * tile;
    const int tw = std::min(tile, W - tx0), th = std::min(tile, H - ty0);
    const auto cells = static_cast<std::size_t>(tw) * static_cast<std::size_t>(th);
    std::vector<double> depth(cells, std::numeric_limits<double>::infinity());
    std::vector<std::uint32_t> winner(cells, std::numeric_limits<std::uint32_t>::max());
    std::vector<float> bary1(cells), bary2(cells);
    for (std::size_t m = offsets[t]; m < offsets[t + 1]; ++m) {
      const std::uint32_t tri = members[m];
      const ScreenVertex &a = sv[mesh.indices[3 * tri]], &b = sv[mesh.indices[3 * tri + 1]], &c = sv[mesh.indices[3 * tri + 2]];
      const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      if (area == 0 || !std::isfinite(area)) continue;
      const double inv = 1.0 / area;
      const Footprint& f = foot[tri];
      for (int py = std::max(f.y0, ty0); py <= std::min(f.y1, ty0 + th - 1); ++py) {
        const double y = py + 0.5;
        for (int px = std::max(f.x0, tx0); px <= std::min(f.x1, tx0 + tw - 1); ++px) {
          const double x = px + 0.5;
          // Barycentric weights of b and c; inside when all three are ≥ 0.
          const double w1 = ((x - a.x) * (c.y - a.y) - (y - a.y) * (c.x - a.x)) * inv;
          const double w2 = ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)) * inv;
          const double w0 = 1.0 - w1 - w2;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          const double z = w0 * a.depth + w1 * b.depth + w2 * c.depth;
          const auto cell = static_cast<std::size_t>(py - ty0) * static_cast<std::size_t>(tw) + static_cast<std::size_t>(px - tx0);
          if (!(z < depth[cell])) continue;
          depth[cell] = z;
          winner[cell] = tri;
          bary1[cell] = static_cast<float>(w1);
          bary2[cell] = static_cast<float>(w2);
        }
      }
    }
    // Shade each covered pixel once.
    for (int py = ty0; py < ty0 + th; ++py)
      for (int px = tx0; px < tx0 + tw; ++px) {
        const auto cell = static_cast<std::size_t>(py - ty0) * static_cast<std::size_t>(tw) + static_cast<std::size_t>(px - tx0);
        const std::uint32_t tri = winner[cell];
        if (tri == std::numeric_limits<std::uint32_t>::max()) continue;
        const double w1 = bary1[cell], w2 = bary2[cell], w0 = 1.0 - w1 - w2;
        const std::uint32_t i0 = mesh.indices[3 * tri], i1 = mesh.indices[3 * tri + 1], i2 = mesh.indices[3 * tri + 2];
        Vec3d n = unit(mesh.normals[i0].cast<double>() * w0 + mesh.normals[i1].cast<double>() * w1 +
                       mesh.normals[i2].cast<double>() * w2);
        Vec3d view = camera.forward * -1.0;
        if (perspective) {
          const Vec3d p = mesh.vertices[i0].cast<double>() * w0 + mesh.vertices[i1].cast<double>() * w1 +
                          mesh.vertices[i2].cast<double>() * w2;
          view = unit(eye - p);
        }
        double nv = dot(n, view);
        if (nv < 0) {  // an inner face seen through a gap: light it as if facing us
          n = n * -1.0;
          nv = -nv;
        }
        const double diffuse = std::max(0.0, dot(n, light));
        const double body = style.ambient + (1.0 - style.ambient) * diffuse;
        const double fresnel = style.fresnel_f0 + (1.0 - style.fresnel_f0) * std::pow(1.0 - nv, 5.0);
        const double highlight = style.specular * std::pow(std::max(0.0, dot(n, unit(light + view))), static_cast<double>(style.shininess));
        auto channel = [&](float deep, float sky) {
          const double v = (1.0 - fresnel) * deep * body + fresnel * sky + highlight;
          return static_cast<float>(std::min(1.0, v));
        };
        image.at(px, py) = {channel(style.deep.r, style.sky.r), channel(style.deep.g, style.sky.g),
                            channel(style.deep.b, style.sky.b)};
      }
  });
}

}  // namespace swirl::render
