#include "swirl/render/colormap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace swirl::render {
namespace {

class ColormapTest : public ::testing::TestWithParam<ColorMap> {};

TEST_P(ColormapTest, HitsEveryStopAtItsValue) {
  const auto stops = colormap_stops(GetParam());
  ASSERT_GE(stops.size(), 2u);
  for (std::size_t k = 0; k < stops.size(); ++k) {
    const double t = static_cast<double>(k) / static_cast<double>(stops.size() - 1);
    const Color c = colormap(GetParam(), t);
    EXPECT_NEAR(c.r, stops[k].r, 1e-6) << "stop " << k;
    EXPECT_NEAR(c.g, stops[k].g, 1e-6) << "stop " << k;
    EXPECT_NEAR(c.b, stops[k].b, 1e-6) << "stop " << k;
  }
}

TEST_P(ColormapTest, InterpolatesLinearlyBetweenStops) {
  const auto stops = colormap_stops(GetParam());
  const double step = 1.0 / static_cast<double>(stops.size() - 1);
  for (std::size_t k = 0; k + 1 < stops.size(); ++k)
    for (double f : {0.25, 0.5, 0.75}) {
      const Color c = colormap(GetParam(), (static_cast<double>(k) + f) * step);
      EXPECT_NEAR(c.r, stops[k].r + f * (stops[k + 1].r - stops[k].r), 1e-5);
      EXPECT_NEAR(c.g, stops[k].g + f * (stops[k + 1].g - stops[k].g), 1e-5);
      EXPECT_NEAR(c.b, stops[k].b + f * (stops[k + 1].b - stops[k].b), 1e-5);
    }
}

TEST_P(ColormapTest, ClampsOutsideTheRangeAndMapsNanToTheBottom) {
  const auto stops = colormap_stops(GetParam());
  EXPECT_EQ(colormap(GetParam(), -3.0), stops.front());
  EXPECT_EQ(colormap(GetParam(), 7.0), stops.back());
  EXPECT_EQ(colormap(GetParam(), std::numeric_limits<double>::quiet_NaN()), stops.front());
  EXPECT_EQ(colormap(GetParam(), std::numeric_limits<double>::infinity()), stops.back());
}

TEST_P(ColormapTest, GetsBrighterFromBottomToTop) {
  // Both maps are designed with monotonically increasing lightness.
  auto luma = [](Color c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; };
  double previous = -1;
  for (int i = 0; i <= 100; ++i) {
    const double l = luma(colormap(GetParam(), i / 100.0));
    EXPECT_GT(l, previous - 1e-3) << "t = " << i / 100.0;
    previous = l;
  }
}

INSTANTIATE_TEST_SUITE_P(Maps, ColormapTest, ::testing::Values(ColorMap::Viridis, ColorMap::Inferno),
                         [](const auto& param_info) { return std::string(colormap_name(param_info.param)); });

}  // namespace
}  // namespace swirl::render
