// Text on rendered images, drawn with FreeType from a TrueType font.
//
// The default font is DejaVu Sans at its Debian path (package
// fonts-dejavu-core). Glyphs are rendered anti-aliased and blended over the
// image; sizes are pixel heights of the em square. Not thread-safe: one Font
// per thread (the renderer draws text serially, after the particles).
#pragma once

#include <filesystem>
#include <memory>
#include <string_view>

#include "swirl/render/image.hpp"

namespace swirl::render {

// /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
std::filesystem::path default_font_path();

class Font {
 public:
  // Loads a font file. Throws io::IoError naming the file (and, for the
  // default font, the Debian package to install) when it cannot be used.
  explicit Font(const std::filesystem::path& file = default_font_path());
  ~Font();
  Font(Font&&) noexcept;
  Font& operator=(Font&&) noexcept;

  // Draws UTF-8 `text` with its baseline at y, starting at x (pixels).
  void draw(Image& image, std::string_view text, int x, int baseline, int pixel_size, Color color) const;

  // The advance width of `text` in pixels.
  int width(std::string_view text, int pixel_size) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swirl::render
