#include "swirl/render/font.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "swirl/io/atomic_file.hpp"

namespace swirl::render {
namespace {

constexpr Color kBlack{0, 0, 0}, kWhite{1, 1, 1};

TEST(Font, DrawsTextWhereItIsAskedTo) {
  const Font font;
  Image image(200, 60, kBlack);
  const int size = 24, x0 = 20, baseline = 40;
  font.draw(image, "t = 0.40 s", x0, baseline, size, kWhite);
  const int width = font.width("t = 0.40 s", size);
  EXPECT_GT(width, 4 * size / 2);
  int lit = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      if (image.at(x, y) != kBlack) {
        ++lit;
        EXPECT_GE(x, x0 - 2);
        EXPECT_LE(x, x0 + width + 2);
        EXPECT_GE(y, baseline - size);     // no glyph here rises above the em
        EXPECT_LE(y, baseline + size / 3);  // nor descends far below the baseline
      }
  EXPECT_GT(lit, 50);
}

TEST(Font, WidthGrowsWithTextAndSize) {
  const Font font;
  EXPECT_EQ(font.width("", 20), 0);
  EXPECT_LT(font.width("1", 20), font.width("10", 20));
  EXPECT_LT(font.width("speed", 12), font.width("speed", 24));
  EXPECT_GT(font.width("kg/m³", 20), font.width("kg/m", 20)) << "UTF-8 superscript drawn";
}

TEST(Font, AMissingFontFileIsNamed) {
  try {
    Font font("/nonexistent/Font.ttf");
    FAIL() << "loaded a missing font";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/Font.ttf"), std::string::npos) << e.what();
  }
}

// A FIFO as the font is refused at once (FreeType would block reading it).
TEST(Font, AFifoIsRefusedNotWaitedOn) {
  const auto fifo = std::filesystem::temp_directory_path() / ("swirl-font-fifo-" + std::to_string(::getpid()));
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    Font font(fifo);
    ADD_FAILURE() << "loaded a FIFO as a font";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("is a FIFO"), std::string::npos) << e.what();
  }
  std::filesystem::remove(fifo);
}

}  // namespace
}  // namespace swirl::render
