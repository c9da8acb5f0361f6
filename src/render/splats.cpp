#include "swirl/render/splats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::render {
namespace {

// A particle on the picture: its disc and its pixel rectangle (inclusive,
// clipped to the image; empty when x0 > x1 or y0 > y1).
struct Splat {
  double x = 0, y = 0, radius = 0, depth = 0;
  Color color;
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  bool visible = false;
};

constexpr std::size_t kProjectBlock = 4096;

// Projects every particle (in parallel, each block its own particles) and
// returns the visible ones in drawing order: far to near, ties by index.
std::vector<Splat> prepare(const Image& image, const Camera& camera, std::span<const Vec3d> positions,
                           std::span<const double> values, const SplatStyle& style) {
  if (values.size() != positions.size()) throw std::invalid_argument("draw_splats: one value per particle");
  std::vector<Splat> splats(positions.size());
  const double span = style.hi - style.lo;
  parallel::for_blocks("render.project", positions.size(), kProjectBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto p = camera.project(positions[i]);
      if (!p) continue;
      Splat& s = splats[i];
      s.x = p->x;
      s.y = p->y;
      s.depth = p->depth;
      s.radius = std::max(style.radius * p->pixels_per_unit, style.min_radius_px);
      s.color = std::isnan(values[i]) ? style.solid : colormap(style.map, span > 0 ? (values[i] - style.lo) / span : 0.0);
      if (!(std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.radius))) continue;
      const double fx0 = std::floor(s.x - s.radius), fx1 = std::ceil(s.x + s.radius);
      const double fy0 = std::floor(s.y - s.radius), fy1 = std::ceil(s.y + s.radius);
      if (fx1 < 0 || fy1 < 0 || fx0 >= image.width() || fy0 >= image.height()) continue;
      s.x0 = static_cast<int>(std::max(fx0, 0.0));
      s.x1 = static_cast<int>(std::min(fx1, image.width() - 1.0));
      s.y0 = static_cast<int>(std::max(fy0, 0.0));
      s.y1 = static_cast<int>(std::min(fy1, image.height() - 1.0));
      s.visible = true;
    }
  });
  std::vector<std::uint32_t> order;
  order.reserve(splats.size());
  for (std::size_t i = 0; i < splats.size(); ++i)
    if (splats[i].visible) order.push_back(static_cast<std::uint32_t>(i));
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (splats[a].depth != splats[b].depth) return splats[a].depth > splats[b].depth;
    return a < b;
  });
  std::vector<Splat> drawn;
  drawn.reserve(order.size());
  for (const auto i : order) drawn.push_back(splats[i]);
  return drawn;
}

// Blends one disc over the pixels of [x0, x1] × [y0, y1] (inclusive) it covers.
void paint(Image& image, const Splat& s, float opacity, int x0, int x1, int y0, int y1) {
  const double inv_r2 = 1.0 / (s.radius * s.radius);
  for (int py = y0; py <= y1; ++py) {
    const double dy = py + 0.5 - s.y;
    for (int px = x0; px <= x1; ++px) {
      const double dx = px + 0.5 - s.x;
      const double q = (dx * dx + dy * dy) * inv_r2;
      if (q >= 1) continue;
      // Opaque core, soft rim; brighter towards the middle like a lit sphere.
      const auto alpha = static_cast<float>(opacity * std::min(1.0, 3.0 * (1.0 - q)));
      const auto shade = static_cast<float>(0.6 + 0.4 * std::sqrt(1.0 - q));
      image.blend(px, py, {s.color.r * shade, s.color.g * shade, s.color.b * shade}, alpha);
    }
  }
}

}  // namespace

void draw_splats(Image& image, const Camera& camera, std::span<const Vec3d> positions,
                 std::span<const double> values, const SplatStyle& style) {
  if (style.tile_size < 1) throw std::invalid_argument("draw_splats: tile size must be at least 1");
  const std::vector<Splat> splats = prepare(image, camera, positions, values, style);
  const int tile = style.tile_size;
  const int tiles_x = (image.width() + tile - 1) / tile, tiles_y = (image.height() + tile - 1) / tile;
  const auto tiles = static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y);

  // Bin the splats to the tiles they touch, keeping drawing order (CSR).
  std::vector<std::size_t> offsets(tiles + 1, 0);
  auto for_each_tile = [&](const Splat& s, auto&& f) {
    for (int ty = s.y0 / tile; ty <= s.y1 / tile; ++ty)
      for (int tx = s.x0 / tile; tx <= s.x1 / tile; ++tx) f(static_cast<std::size_t>(ty) * tiles_x + tx);
  };
  for (const Splat& s : splats) for_each_tile(s, [&](std::size_t t) { ++offsets[t + 1]; });
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::uint32_t> members(offsets.back());
  std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t k = 0; k < splats.size(); ++k)
    for_each_tile(splats[k], [&](std::size_t t) { members[fill[t]++] = static_cast<std::uint32_t>(k); });

  // Each tile blends only its own pixels, in drawing order.
  parallel::for_blocks("render.splats", tiles, 1, [&](std::size_t t, std::size_t, std::size_t) {
    const int tx0 = static_cast<int>(t % static_cast<std::size_t>(tiles_x)) * tile;
    const int ty0 = static_cast<int>(t / static_cast<std::size_t>(tiles_x)) * tile;
    const int tx1 = std::min(tx0 + tile, image.width()) - 1, ty1 = std::min(ty0 + tile, image.height()) - 1;
    for (std::size_t m = offsets[t]; m < offsets[t + 1]; ++m) {
      const Splat& s = splats[members[m]];
      paint(image, s, style.opacity, std::max(s.x0, tx0), std::min(s.x1, tx1), std::max(s.y0, ty0),
            std::min(s.y1, ty1));
    }
  });
}

void draw_splats_reference(Image& image, const Camera& camera, std::span<const Vec3d> positions,
                           std::span<const double> values, const SplatStyle& style) {
  for (const Splat& s : prepare(image, camera, positions, values, style))
    paint(image, s, style.opacity, s.x0, s.x1, s.y0, s.y1);
}

}  // namespace swirl::render
