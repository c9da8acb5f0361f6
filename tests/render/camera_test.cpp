#include "swirl/render/camera.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace swirl::render {
namespace {

constexpr Box<double> kBox{{0, 0, 0}, {2, 1, 1}};

TEST(Camera, ViewsAreOrthonormalFrames) {
  for (View view : {View::Front, View::Top, View::Iso}) {
    Vec3d f, r, u;
    view_axes(view, f, r, u);
    EXPECT_NEAR(dot(f, f), 1, 1e-12);
    EXPECT_NEAR(dot(r, r), 1, 1e-12);
    EXPECT_NEAR(dot(u, u), 1, 1e-12);
    EXPECT_NEAR(dot(f, r), 0, 1e-12);
    EXPECT_NEAR(dot(f, u), 0, 1e-12);
    EXPECT_NEAR(dot(r, u), 0, 1e-12);
    EXPECT_GT(r.x, 0) << "x runs to the right in every view";
  }
}

TEST(Camera, OrthographicFitCentresTheBoxAndKeepsItInside) {
  for (View view : {View::Front, View::Top, View::Iso}) {
    const Camera c = Camera::fit(kBox, view, Projection::Orthographic, 10, 20, 300, 200);
    double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
    for (int i = 0; i < 8; ++i) {
      const Vec3d corner{(i & 1) ? 2.0 : 0.0, (i & 2) ? 1.0 : 0.0, (i & 4) ? 1.0 : 0.0};
      const auto p = c.project(corner);
      ASSERT_TRUE(p);
      xmin = std::min(xmin, p->x), xmax = std::max(xmax, p->x);
      ymin = std::min(ymin, p->y), ymax = std::max(ymax, p->y);
    }
    EXPECT_GE(xmin, 10);
    EXPECT_LE(xmax, 310);
    EXPECT_GE(ymin, 20);
    EXPECT_LE(ymax, 220);
    EXPECT_NEAR(0.5 * (xmin + xmax), 160, 1e-9);
    EXPECT_NEAR(0.5 * (ymin + ymax), 120, 1e-9);
    // It fills the region along at least one axis.
    EXPECT_TRUE(xmax - xmin > 0.9 * 300 || ymax - ymin > 0.9 * 200);
  }
}

TEST(Camera, FrontViewPutsXRightAndZUp) {
  const Camera c = Camera::fit(kBox, View::Front, Projection::Orthographic, 0, 0, 300, 200);
  const auto a = c.project({0, 0.5, 0}), b = c.project({2, 0.5, 0}), top = c.project({0, 0.5, 1});
  EXPECT_GT(b->x, a->x);
  EXPECT_LT(top->y, a->y);
  EXPECT_NEAR(b->x - a->x, 2 * c.scale, 1e-9);
  // y is depth: it does not move the picture, only the depth.
  const auto behind = c.project({0, 1, 0});
  EXPECT_EQ(behind->x, a->x);
  EXPECT_EQ(behind->y, a->y);
  EXPECT_GT(behind->depth, a->depth);
}

TEST(Camera, PerspectiveShrinksWithDistanceAndFitsTheBox) {
  const Camera c = Camera::fit(kBox, View::Front, Projection::Perspective, 0, 0, 300, 200);
  const auto nearer = c.project({1, 0, 0.5}), farther = c.project({1, 1, 0.5});
  ASSERT_TRUE(nearer && farther);
  EXPECT_GT(nearer->pixels_per_unit, farther->pixels_per_unit);
  EXPECT_LT(nearer->depth, farther->depth);
  for (int i = 0; i < 8; ++i) {
    const auto p = c.project({(i & 1) ? 2.0 : 0.0, (i & 2) ? 1.0 : 0.0, (i & 4) ? 1.0 : 0.0});
    ASSERT_TRUE(p);
    EXPECT_GE(p->x, 0);
    EXPECT_LE(p->x, 300);
    EXPECT_GE(p->y, 0);
    EXPECT_LE(p->y, 200);
  }
}

TEST(Camera, ParsesNamesAndRefusesOthers) {
  EXPECT_EQ(parse_view("top"), View::Top);
  EXPECT_EQ(parse_projection("perspective"), Projection::Perspective);
  EXPECT_THROW(parse_view("side"), std::invalid_argument);
  EXPECT_THROW(parse_projection("fisheye"), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::render
