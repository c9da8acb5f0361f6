// An RGB image in memory: what the renderer draws into before it is encoded.
//
// Pixels are stored row by row from the top-left corner, three floats per
// pixel (red, green, blue) in [0, 1] as they will appear on screen (sRGB
// values, no gamma conversion). Pixel (x, y) covers [x, x+1) × [y, y+1) in
// image coordinates, so its centre is (x + ½, y + ½); y grows downwards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace swirl::render {

struct Color {
  float r = 0, g = 0, b = 0;
  friend constexpr bool operator==(const Color&, const Color&) = default;
};

class Image {
 public:
  Image() = default;
  // A width × height image filled with `background`; both sizes ≥ 1.
  Image(int width, int height, Color background = {}) : width_(width), height_(height) {
    if (width < 1 || height < 1) throw std::invalid_argument("image size must be at least 1x1");
    pixels_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), background);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  Color& at(int x, int y) { return pixels_[index(x, y)]; }
  const Color& at(int x, int y) const { return pixels_[index(x, y)]; }
  bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  const std::vector<Color>& pixels() const { return pixels_; }

  // Blends `c` over pixel (x, y) with opacity alpha in [0, 1]; outside: nothing.
  void blend(int x, int y, Color c, float alpha) {
    if (!contains(x, y)) return;
    Color& p = at(x, y);
    p.r += (c.r - p.r) * alpha;
    p.g += (c.g - p.g) * alpha;
    p.b += (c.b - p.b) * alpha;
  }

 private:
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }
  int width_ = 0, height_ = 0;
  std::vector<Color> pixels_;
};

// One colour channel in [0, 1] as an 8-bit value (rounded, clamped).
inline std::uint8_t to_byte(float v) {
  const float c = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
  return static_cast<std::uint8_t>(c * 255.0f + 0.5f);
}

// The image as 8-bit RGB bytes, row by row from the top.
inline std::vector<std::uint8_t> to_rgb8(const Image& image) {
  std::vector<std::uint8_t> out;
  out.reserve(image.pixels().size() * 3);
  for (const Color& c : image.pixels()) {
    out.push_back(to_byte(c.r));
    out.push_back(to_byte(c.g));
    out.push_back(to_byte(c.b));
  }
  return out;
}

}  // namespace swirl::render
