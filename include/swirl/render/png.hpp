// PNG files of rendered images (libpng), written atomically.
//
// encode_png() turns an Image into the bytes of an 8-bit RGB PNG in memory;
// write_png() writes them with io::write_file_atomic, so a failure leaves no
// partial file. read_png() reads any PNG back as 8-bit RGB (for checks).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "swirl/render/image.hpp"

namespace swirl::render {

// The bytes of an 8-bit RGB PNG of `image`.
std::string encode_png(const Image& image);

// Writes `image` as a PNG to `path` atomically. Throws io::IoError.
void write_png(const std::filesystem::path& path, const Image& image);

// A PNG read back as 8-bit RGB rows from the top.
struct Rgb8Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // 3 bytes per pixel
};

// Reads a PNG file. Throws io::IoError naming the file and libpng's reason.
Rgb8Image read_png(const std::filesystem::path& path);

}  // namespace swirl::render
