#include "swirl/render/png.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "render/render_test_util.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::render {
namespace {

Image gradient(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      image.at(x, y) = {static_cast<float>(x) / static_cast<float>(w - 1), static_cast<float>(y) / static_cast<float>(h - 1),
                        static_cast<float>((x * 7 + y * 3) % 256) / 255.0f};
  return image;
}

TEST(Png, WritesWhatReadsBack) {
  test::TempDir dir;
  const Image image = gradient(37, 23);
  const auto path = dir.path / "g.png";
  write_png(path, image);
  const Rgb8Image back = read_png(path);
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.rgb, to_rgb8(image));
  EXPECT_EQ(io::read_text_file(path), encode_png(image)) << "encoding is deterministic";
}

TEST(Png, ConvertsChannelsByRoundingAndClamping) {
  EXPECT_EQ(to_byte(0.0f), 0);
  EXPECT_EQ(to_byte(1.0f), 255);
  EXPECT_EQ(to_byte(-0.5f), 0);
  EXPECT_EQ(to_byte(2.0f), 255);
  EXPECT_EQ(to_byte(0.5f), 128);
  EXPECT_EQ(to_byte(100.0f / 255.0f), 100);
}

TEST(Png, AFailedWriteLeavesNoFile) {
  test::TempDir dir;
  const auto path = dir.path / "missing_folder" / "x.png";
  EXPECT_THROW(write_png(path, gradient(4, 4)), io::IoError);
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path));
}

TEST(Png, ReadingGarbageNamesTheFile) {
  test::TempDir dir;
  const auto path = dir.path / "bad.png";
  std::ofstream(path) << "this is not a png";
  try {
    read_png(path);
    FAIL() << "read a file that is not a PNG";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swirl::render
