#include "swirl/render/surface_density.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::render {
namespace {

// One particle's deposit: Σ at a pixel = scale · (1 − d²/R²)².
struct Deposit {
  double x = 0, y = 0, scale = 0, inv_r2 = 0;
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;  // pixels it reaches on the grid (inclusive)
};

constexpr std::size_t kProjectBlock = 4096;
constexpr int kCountCell = 8;  // pixels per side of the cells that estimate the adaptive radius
constexpr double kPi = 3.14159265358979323846;

double weight(double dx, double dy, double inv_r2) {
  const double q = 1.0 - (dx * dx + dy * dy) * inv_r2;
  return q > 0 ? q * q : 0.0;
}

// Kernel radius per projected particle: fixed, or from the particle count in
// the 3×3 cells around it (integer counts, so no order dependence).
std::vector<double> kernel_radii(const std::vector<Projected>& proj, const std::vector<char>& visible, int width,
                                 int height, const DensityKernel& kernel) {
  std::vector<double> radius(proj.size(), kernel.min_px);
  if (!(kernel.neighbours > 0)) return radius;
  const int margin = static_cast<int>(std::ceil(kernel.max_px)) + kCountCell;
  const int cells_x = (width + 2 * margin) / kCountCell + 1, cells_y = (height + 2 * margin) / kCountCell + 1;
  auto cell_of = [&](const Projected& p, int& cx, int& cy) {
    cx = static_cast<int>(std::floor((p.x + margin) / kCountCell));
    cy = static_cast<int>(std::floor((p.y + margin) / kCountCell));
    return cx >= 0 && cy >= 0 && cx < cells_x && cy < cells_y;
  };
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(cells_x) * cells_y, 0);
  for (std::size_t i = 0; i < proj.size(); ++i) {
    int cx, cy;
    if (visible[i] && cell_of(proj[i], cx, cy)) ++counts[static_cast<std::size_t>(cy) * cells_x + cx];
  }
  parallel::for_blocks("render.density.radius", proj.size(), kProjectBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      int cx, cy;
      if (!visible[i] || !cell_of(proj[i], cx, cy)) {
        radius[i] = kernel.max_px;
        continue;
      }
      std::uint64_t n = 0;
      for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, cells_y - 1); ++y)
        for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, cells_x - 1); ++x)
          n += counts[static_cast<std::size_t>(y) * cells_x + x];
      const double per_px2 = static_cast<double>(n) / (9.0 * kCountCell * kCountCell);
      radius[i] = std::clamp(std::sqrt(kernel.neighbours / (kPi * per_px2)), kernel.min_px, kernel.max_px);
    }
  });
  return radius;
}

// The deposits of the particles whose footprint touches the grid, in particle order.
std::vector<Deposit> prepare(const Camera& camera, int width, int height, std::span<const Vec3d> positions,
                             std::span<const double> masses, const DensityKernel& kernel) {
  if (masses.size() != positions.size()) throw std::invalid_argument("surface_density: one mass per particle");
  if (!(kernel.min_px >= 0.75)) throw std::invalid_argument("surface_density: kernel radius must be at least 0.75 px");
  if (kernel.neighbours > 0 && !(kernel.max_px >= kernel.min_px && kernel.max_px <= 1000))
    throw std::invalid_argument("surface_density: the largest kernel radius must lie between min_px and 1000 px");
  if (width < 1 || height < 1) throw std::invalid_argument("surface_density: empty grid");
  const std::size_t n = positions.size();
  std::vector<Projected> proj(n);
  std::vector<char> visible(n, 0);
  parallel::for_blocks("render.density.project", n, kProjectBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto p = camera.project(positions[i]);
      if (!p || !std::isfinite(p->x) || !std::isfinite(p->y) || std::abs(p->x) > 1e9 || std::abs(p->y) > 1e9) continue;
      proj[i] = *p;
      visible[i] = 1;
    }
  });
  const std::vector<double> radius = kernel_radii(proj, visible, width, height, kernel);
  std::vector<Deposit> all(n);
  parallel::for_blocks("render.density.kernel", n, kProjectBlock, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!visible[i]) continue;
      const Projected& p = proj[i];
      const double r = radius[i], inv_r2 = 1.0 / (r * r);
      const double fx0 = std::floor(p.x - r), fx1 = std::ceil(p.x + r);
      const double fy0 = std::floor(p.y - r), fy1 = std::ceil(p.y + r);
      if (fx1 < 0 || fy1 < 0 || fx0 >= width || fy0 >= height) continue;
      // Normalise over the whole footprint (also the part off the grid), so a
      // particle weighs the same wherever it lands on the pixel lattice.
      double total = 0;
      for (double py = fy0; py <= fy1; ++py)
        for (double px = fx0; px <= fx1; ++px) total += weight(px + 0.5 - p.x, py + 0.5 - p.y, inv_r2);
      Deposit& d = all[i];
      d.x = p.x;
      d.y = p.y;
      d.inv_r2 = inv_r2;
      d.scale = masses[i] * p.pixels_per_unit * p.pixels_per_unit / total;
      d.x0 = static_cast<int>(std::max(fx0, 0.0));
      d.x1 = static_cast<int>(std::min(fx1, width - 1.0));
      d.y0 = static_cast<int>(std::max(fy0, 0.0));
      d.y1 = static_cast<int>(std::min(fy1, height - 1.0));
    }
  });
  std::vector<Deposit> kept;
  for (const Deposit& d : all)
    if (d.x0 <= d.x1 && d.y0 <= d.y1) kept.push_back(d);
  return kept;
}

void deposit(DensityMap& map, const Deposit& d, int x0, int x1, int y0, int y1) {
  for (int py = y0; py <= y1; ++py)
    for (int px = x0; px <= x1; ++px)
      map.sigma[static_cast<std::size_t>(py) * map.width + px] += d.scale * weight(px + 0.5 - d.x, py + 0.5 - d.y, d.inv_r2);
}

}  // namespace

DensityMap surface_density(const Camera& camera, int width, int height, std::span<const Vec3d> positions,
                           std::span<const double> masses, const DensityKernel& kernel, int tile_size) {
  if (tile_size < 1) throw std::invalid_argument("surface_density: tile size must be at least 1");
  const std::vector<Deposit> deposits = prepare(camera, width, height, positions, masses, kernel);
  DensityMap map{width, height, std::vector<double>(static_cast<std::size_t>(width) * height, 0.0)};
  const int tile = tile_size;
  const int tiles_x = (width + tile - 1) / tile, tiles_y = (height + tile - 1) / tile;
  const auto tiles = static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y);
  std::vector<std::size_t> offsets(tiles + 1, 0);
  auto for_each_tile = [&](const Deposit& d, auto&& f) {
    for (int ty = d.y0 / tile; ty <= d.y1 / tile; ++ty)
      for (int tx = d.x0 / tile; tx <= d.x1 / tile; ++tx) f(static_cast<std::size_t>(ty) * tiles_x + tx);
  };
  for (const Deposit& d : deposits) for_each_tile(d, [&](std::size_t t) { ++offsets[t + 1]; });
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::uint32_t> members(offsets.back());
  std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t k = 0; k < deposits.size(); ++k)
    for_each_tile(deposits[k], [&](std::size_t t) { members[fill[t]++] = static_cast<std::uint32_t>(k); });
  parallel::for_blocks("render.density", tiles, 1, [&](std::size_t t, std::size_t, std::size_t) {
    const int tx0 = static_cast<int>(t % static_cast<std::size_t>(tiles_x)) * tile;
    const int ty0 = static_cast<int>(t / static_cast<std::size_t>(tiles_x)) * tile;
    const int tx1 = std::min(tx0 + tile, width) - 1, ty1 = std::min(ty0 + tile, height) - 1;
    for (std::size_t m = offsets[t]; m < offsets[t + 1]; ++m) {
      const Deposit& d = deposits[members[m]];
      deposit(map, d, std::max(d.x0, tx0), std::min(d.x1, tx1), std::max(d.y0, ty0), std::min(d.y1, ty1));
    }
  });
  return map;
}

DensityMap surface_density_reference(const Camera& camera, int width, int height,
                                     std::span<const Vec3d> positions, std::span<const double> masses,
                                     const DensityKernel& kernel) {
  const std::vector<Deposit> deposits = prepare(camera, width, height, positions, masses, kernel);
  DensityMap map{width, height, std::vector<double>(static_cast<std::size_t>(width) * height, 0.0)};
  for (const Deposit& d : deposits) deposit(map, d, d.x0, d.x1, d.y0, d.y1);
  return map;
}

void draw_log_density(Image& image, const DensityMap& density, ColorMap map, double log_lo, double log_hi) {
  if (image.width() != density.width || image.height() != density.height)
    throw std::invalid_argument("draw_log_density: image and density map differ in size");
  const double span = log_hi - log_lo;
  parallel::for_blocks("render.density.colour", static_cast<std::size_t>(image.height()), 16,
                       [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t y = begin; y < end; ++y)
      for (int x = 0; x < image.width(); ++x) {
        const double s = density.at(x, static_cast<int>(y));
        const double t = s > 0 && span > 0 ? (std::log10(s) - log_lo) / span : 0.0;
        image.at(x, static_cast<int>(y)) = colormap(map, t);
      }
  });
}

}  // namespace swirl::render
