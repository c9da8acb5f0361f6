#include "swirl/render/font.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <string>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/read_file.hpp"

namespace swirl::render {
namespace {

// Next code point of UTF-8 text (invalid bytes come out as U+FFFD).
char32_t next_code_point(std::string_view text, std::size_t& i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b0 = byte(i);
  int extra = b0 < 0x80 ? 0 : (b0 >> 5) == 0x6 ? 1 : (b0 >> 4) == 0xe ? 2 : (b0 >> 3) == 0x1e ? 3 : -1;
  if (extra < 0 || i + static_cast<std::size_t>(extra) >= text.size()) {
    ++i;
    return 0xfffd;
  }
  char32_t cp = extra == 0 ? b0 : (b0 & (0x3f >> extra));
  for (int k = 1; k <= extra; ++k) {
    const unsigned char b = byte(i + static_cast<std::size_t>(k));
    if ((b >> 6) != 0x2) {
      ++i;
      return 0xfffd;
    }
    cp = (cp << 6) | (b & 0x3f);
  }
  i += static_cast<std::size_t>(extra) + 1;
  return cp;
}

}  // namespace

std::filesystem::path default_font_path() { return "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"; }

struct Font::Impl {
  std::string bytes;  // the font file; FreeType reads from it for the face's lifetime
  FT_Library library = nullptr;
  FT_Face face = nullptr;
  ~Impl() {
    if (face) FT_Done_Face(face);
    if (library) FT_Done_FreeType(library);
  }
  void set_size(int pixel_size) const {
    FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixel_size < 1 ? 1 : pixel_size));
  }
};

Font::Font(const std::filesystem::path& file) : impl_(std::make_unique<Impl>()) {
  const std::string hint = file == default_font_path() ? " (install Debian's fonts-dejavu-core: make deps)" : "";
  if (!std::filesystem::exists(file)) throw io::IoError(file.string() + ": font file not found" + hint);
  // Read by io's one reader (a regular file of font size, never a FIFO),
  // then handed to FreeType from memory.
  impl_->bytes = io::read_regular_file(file, io::kMaxFontBytes);
  if (FT_Init_FreeType(&impl_->library) != 0) throw io::IoError("FreeType could not be initialised");
  if (FT_New_Memory_Face(impl_->library, reinterpret_cast<const FT_Byte*>(impl_->bytes.data()),
                         static_cast<FT_Long>(impl_->bytes.size()), 0, &impl_->face) != 0)
    throw io::IoError(file.string() + ": not a font FreeType can read" + hint);
}

Font::~Font() = default;
Font::Font(Font&&) noexcept = default;
Font& Font::operator=(Font&&) noexcept = default;

void Font::draw(Image& image, std::string_view text, int x, int baseline, int pixel_size, Color color) const {
  impl_->set_size(pixel_size);
  FT_Face face = impl_->face;
  long pen = static_cast<long>(x) * 64;  // 26.6 fixed point
  for (std::size_t i = 0; i < text.size();) {
    const char32_t cp = next_code_point(text, i);
    if (FT_Load_Char(face, cp, FT_LOAD_RENDER) != 0) continue;
    const FT_GlyphSlot g = face->glyph;
    const FT_Bitmap& bm = g->bitmap;
    const int left = static_cast<int>(pen >> 6) + g->bitmap_left;
    const int top = baseline - g->bitmap_top;
    for (unsigned row = 0; row < bm.rows; ++row)
      for (unsigned col = 0; col < bm.width; ++col) {
        const unsigned char coverage = bm.buffer[static_cast<long>(row) * bm.pitch + col];
        if (coverage) image.blend(left + static_cast<int>(col), top + static_cast<int>(row), color, coverage / 255.0f);
      }
    pen += g->advance.x;
  }
}

int Font::width(std::string_view text, int pixel_size) const {
  impl_->set_size(pixel_size);
  long pen = 0;
  for (std::size_t i = 0; i < text.size();) {
    const char32_t cp = next_code_point(text, i);
    if (FT_Load_Char(impl_->face, cp, FT_LOAD_DEFAULT) == 0) pen += impl_->face->glyph->advance.x;
  }
  return static_cast<int>(pen >> 6);
}

}  // namespace swirl::render
