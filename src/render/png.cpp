// PNG encoding and decoding with libpng's simplified API (png_image), which
// reports errors through return values instead of longjmp.
#include "swirl/render/png.hpp"

#include <png.h>

#include <cstring>
#include <string>
#include <vector>

#include "swirl/io/atomic_file.hpp"

namespace swirl::render {

std::string encode_png(const Image& image) {
  const std::vector<std::uint8_t> rgb = to_rgb8(image);
  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  info.width = static_cast<png_uint_32>(image.width());
  info.height = static_cast<png_uint_32>(image.height());
  info.format = PNG_FORMAT_RGB;
  // Speed over size: zlib at its default level took most of a frame's time.
  info.flags = PNG_IMAGE_FLAG_FAST;
  const png_int_32 stride = image.width() * 3;
  png_alloc_size_t size = 0;
  if (!png_image_write_get_memory_size(info, size, 0, rgb.data(), stride, nullptr))
    throw io::IoError(std::string("PNG encoding failed: ") + info.message);
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&info, bytes.data(), &size, 0, rgb.data(), stride, nullptr))
    throw io::IoError(std::string("PNG encoding failed: ") + info.message);
  bytes.resize(size);
  return bytes;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  io::write_file_atomic(path, encode_png(image));
}

Rgb8Image read_png(const std::filesystem::path& path) {
  const std::string bytes = io::read_text_file(path);
  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&info, bytes.data(), bytes.size()))
    throw io::IoError(path.string() + ": not a readable PNG (" + info.message + ")");
  info.format = PNG_FORMAT_RGB;
  Rgb8Image out;
  out.width = static_cast<int>(info.width);
  out.height = static_cast<int>(info.height);
  out.rgb.resize(PNG_IMAGE_SIZE(info));
  if (!png_image_finish_read(&info, nullptr, out.rgb.data(), 0, nullptr)) {
    const std::string reason = info.message;
    png_image_free(&info);
    throw io::IoError(path.string() + ": not a readable PNG (" + reason + ")");
  }
  return out;
}

}  // namespace swirl::render
