#include "swirl/render/splats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "render/render_test_util.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::render {
namespace {

using test::front_camera;

constexpr Color kBackground{0.1f, 0.2f, 0.3f};

// Blending is a float lerp, so "exactly the map's colour" holds to rounding.
void expect_colour(const Color& got, const Color& want, const std::string& where) {
  EXPECT_NEAR(got.r, want.r, 1e-6) << where;
  EXPECT_NEAR(got.g, want.g, 1e-6) << where;
  EXPECT_NEAR(got.b, want.b, 1e-6) << where;
}

SplatStyle opaque_style(double radius) {
  SplatStyle s;
  s.radius = radius;
  s.opacity = 1.0f;
  s.lo = 0;
  s.hi = 1;
  return s;
}

// True when the pixel centre (x + ½, y + ½) is strictly inside the disc.
bool inside(int x, int y, double cx, double cy, double r) {
  const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
  return dx * dx + dy * dy < r * r;
}

TEST(Splats, OneParticleAtTheCentreCoversExactlyItsDisc) {
  const int w = 101, h = 81;
  const double scale = 10, radius = 0.5;  // 5 px
  const Camera camera = front_camera(50.5, 40.5, scale);
  Image image(w, h, kBackground);
  const std::vector<Vec3d> p{{0, 0, 0}};
  const std::vector<double> v{0.5};
  draw_splats(image, camera, p, v, opaque_style(radius));
  int painted = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool in = inside(x, y, 50.5, 40.5, radius * scale);
      EXPECT_EQ(image.at(x, y) != kBackground, in) << "pixel " << x << "," << y;
      painted += in;
    }
  EXPECT_GT(painted, 60);  // about π·5² pixels
  // The middle pixel is fully opaque and fully lit: exactly the map's colour.
  expect_colour(image.at(50, 40), colormap(ColorMap::Viridis, 0.5), "centre");
}

TEST(Splats, ALineAlongXPaintsOneBandOfRows) {
  const int w = 200, h = 60;
  const double scale = 40, radius = 0.05;  // 2 px
  const Camera camera = front_camera(100, 30, scale);
  std::vector<Vec3d> p;
  std::vector<double> v;
  for (int i = -20; i <= 20; ++i) {  // x from -2 to 2 every 0.1 (4 px apart), z = 0
    p.push_back({0.1 * i, 0.3, 0});
    v.push_back(0.0);
  }
  Image image(w, h, kBackground);
  draw_splats(image, camera, p, v, opaque_style(radius));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool expected = false;
      for (const auto& q : p) expected = expected || inside(x, y, 100 + scale * q.x, 30, radius * scale);
      EXPECT_EQ(image.at(x, y) != kBackground, expected) << "pixel " << x << "," << y;
    }
  // The band runs from x = 100 − 80 − 2 to 100 + 80 + 2 on the rows around y = 30.
  EXPECT_NE(image.at(20, 29), kBackground);
  EXPECT_NE(image.at(179, 30), kBackground);
  EXPECT_EQ(image.at(100, 20), kBackground);
}

TEST(Splats, TheNearerParticleIsDrawnOverTheFarther) {
  const Camera camera = front_camera(20.5, 20.5, 10);  // pixel (20, 20) has its centre there
  // Front view looks along +y: y = −1 is nearer than y = +1.
  for (bool near_first : {true, false}) {
    std::vector<Vec3d> p{{0, -1, 0}, {0, 1, 0}};
    std::vector<double> v{1.0, 0.0};
    if (!near_first) {
      std::swap(p[0], p[1]);
      std::swap(v[0], v[1]);
    }
    Image image(40, 40, kBackground);
    draw_splats(image, camera, p, v, opaque_style(0.5));
    expect_colour(image.at(20, 20), colormap(ColorMap::Viridis, 1.0), near_first ? "near listed first" : "far listed first");
  }
}

TEST(Splats, ColoursFollowTheMapOverTheRange) {
  const Camera camera = front_camera(50, 10, 10);
  SplatStyle style = opaque_style(0.5);
  style.lo = 10;
  style.hi = 30;
  std::vector<Vec3d> p;
  std::vector<double> v;
  for (int i = 0; i < 5; ++i) {
    p.push_back({-4.0 + 2.0 * i, 0, 0});
    v.push_back(5.0 + 7.0 * i);  // 5 (below the range) ... 33 (above)
  }
  Image image(100, 20, kBackground);
  draw_splats(image, camera, p, v, style);
  for (int i = 0; i < 5; ++i) {
    const int x = 50 + static_cast<int>(std::lround(10 * p[i].x));
    // Pixel (x, 10) has its centre 0.5 px from the particle in each axis.
    const double q = (0.25 + 0.25) / 25.0;
    const float shade = static_cast<float>(0.6 + 0.4 * std::sqrt(1.0 - q));
    const Color c = colormap(ColorMap::Viridis, (v[i] - 10) / 20);
    EXPECT_NEAR(image.at(x, 10).r, c.r * shade, 1e-6) << "value " << v[i];
    EXPECT_NEAR(image.at(x, 10).g, c.g * shade, 1e-6) << "value " << v[i];
    EXPECT_NEAR(image.at(x, 10).b, c.b * shade, 1e-6) << "value " << v[i];
  }
}

TEST(Splats, ParticlesBehindAPerspectiveEyeAreSkipped) {
  Camera camera = Camera::fit({{0, 0, 0}, {1, 1, 1}}, View::Front, Projection::Perspective, 0, 0, 64, 64);
  const Vec3d eye = camera.target - camera.forward * camera.distance;
  Image image(64, 64, kBackground);
  const std::vector<Vec3d> p{eye - camera.forward * 0.5, eye};
  const std::vector<double> v{0.5, 0.5};
  draw_splats(image, camera, p, v, opaque_style(0.2));
  for (const Color& c : image.pixels()) EXPECT_EQ(c, kBackground);
}

// The tiled, parallel renderer against the serial slow twin: bit-identical for
// any tile size and thread count, orthographic and perspective.
TEST(Splats, TiledEqualsTheReferenceForAnyThreadCountAndTileSize) {
  const auto p = test::random_cloud(3000, 7, -0.2, 1.2);  // some off the picture
  const auto v = test::random_values(p.size(), 8);
  const int saved = parallel::thread_count();
  for (Projection projection : {Projection::Orthographic, Projection::Perspective}) {
    const Camera camera = Camera::fit({{0, 0, 0}, {1, 1, 1}}, View::Iso, projection, 0, 0, 157, 93);
    SplatStyle style;
    style.radius = 0.02;
    style.lo = 0.1;
    style.hi = 0.9;
    Image reference(157, 93, kBackground);
    draw_splats_reference(reference, camera, p, v, style);
    for (int threads : {1, 2, 3})
      for (int tile : {1, 7, 32, 500}) {
        parallel::set_thread_count(threads);
        style.tile_size = tile;
        Image image(157, 93, kBackground);
        draw_splats(image, camera, p, v, style);
        ASSERT_EQ(image.pixels(), reference.pixels()) << "threads " << threads << ", tile " << tile;
      }
  }
  parallel::set_thread_count(saved);
}

TEST(Splats, RefusesMismatchedInput) {
  Image image(10, 10);
  const std::vector<Vec3d> p{{0, 0, 0}};
  const std::vector<double> none;
  EXPECT_THROW(draw_splats(image, front_camera(5, 5, 1), p, none, SplatStyle{}), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::render
