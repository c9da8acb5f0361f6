#include "swirl/render/colormap.hpp"

#include <array>
#include <cmath>
#include <cstdint>

namespace swirl::render {
namespace {

constexpr Color hex(std::uint32_t rgb) {
  return {static_cast<float>((rgb >> 16) & 0xff) / 255.0f, static_cast<float>((rgb >> 8) & 0xff) / 255.0f,
          static_cast<float>(rgb & 0xff) / 255.0f};
}

// Ten evenly spaced samples of each map.
constexpr std::array<Color, 10> kViridis{hex(0x440154), hex(0x482878), hex(0x3e4989), hex(0x31688e), hex(0x26828e),
                                         hex(0x1f9e89), hex(0x35b779), hex(0x6ece58), hex(0xb5de2b), hex(0xfde725)};
constexpr std::array<Color, 10> kInferno{hex(0x000004), hex(0x1b0c41), hex(0x4a0c6b), hex(0x781c6d), hex(0xa52c60),
                                         hex(0xcf4446), hex(0xed6925), hex(0xfb9b06), hex(0xf7d13d), hex(0xfcffa4)};

}  // namespace

std::span<const Color> colormap_stops(ColorMap map) {
  return map == ColorMap::Viridis ? std::span<const Color>(kViridis) : std::span<const Color>(kInferno);
}

Color colormap(ColorMap map, double t) {
  const auto stops = colormap_stops(map);
  if (!(t > 0)) return stops.front();  // also NaN
  if (t >= 1) return stops.back();
  const double s = t * static_cast<double>(stops.size() - 1);
  const auto k = static_cast<std::size_t>(s);
  const auto f = static_cast<float>(s - static_cast<double>(k));
  const Color a = stops[k], b = stops[k + 1];
  return {a.r + (b.r - a.r) * f, a.g + (b.g - a.g) * f, a.b + (b.b - a.b) * f};
}

std::string_view colormap_name(ColorMap map) { return map == ColorMap::Viridis ? "viridis" : "inferno"; }

}  // namespace swirl::render
