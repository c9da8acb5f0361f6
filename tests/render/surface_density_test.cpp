#include "swirl/render/surface_density.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "render/render_test_util.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::render {
namespace {

using test::front_camera;

constexpr double kPiForTest = 3.14159265358979323846;

double total(const DensityMap& m) { return std::accumulate(m.sigma.begin(), m.sigma.end(), 0.0); }

TEST(SurfaceDensity, KeepsTheMassOfParticlesInsideThePicture) {
  const double scale = 50;  // px per unit: a pixel's area is 1/50² units²
  const Camera camera = front_camera(60, 40, scale);
  const auto p = test::random_cloud(500, 3, -0.5, 0.5);
  std::vector<double> m(p.size());
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = 0.5 + 0.001 * static_cast<double>(i);
  const DensityMap map = surface_density(camera, 120, 80, p, m, DensityKernel{1.7});
  const double mass = std::accumulate(m.begin(), m.end(), 0.0);
  EXPECT_NEAR(total(map) / (scale * scale), mass, 1e-9 * mass);
}

TEST(SurfaceDensity, OneParticleAtAPixelCentreIsSymmetricAndPeaksThere) {
  const Camera camera = front_camera(20.5, 20.5, 10);
  const std::vector<Vec3d> p{{0, 0, 0}};
  const std::vector<double> m{2.0};
  const DensityMap map = surface_density(camera, 41, 41, p, m, DensityKernel{3.0});
  const double peak = map.at(20, 20);
  EXPECT_GT(peak, 0);
  for (int y = 0; y < 41; ++y)
    for (int x = 0; x < 41; ++x) {
      EXPECT_LE(map.at(x, y), peak);
      EXPECT_DOUBLE_EQ(map.at(x, y), map.at(40 - x, y));
      EXPECT_DOUBLE_EQ(map.at(x, y), map.at(y, x));
      const double d2 = (x - 20) * (x - 20) + (y - 20) * (y - 20);
      EXPECT_EQ(map.at(x, y) > 0, d2 < 9.0) << x << "," << y;
    }
  EXPECT_NEAR(total(map) / 100.0, 2.0, 1e-12);
}

TEST(SurfaceDensity, TiledEqualsTheReferenceForAnyThreadCount) {
  auto p = test::random_cloud(4000, 11, -0.3, 1.3);
  for (auto& q : test::random_cloud(2000, 13, 0.4, 0.5)) p.push_back(q);  // a dense core
  const auto m = test::random_values(p.size(), 12);
  const int saved = parallel::thread_count();
  for (const DensityKernel kernel : {DensityKernel{1.5}, DensityKernel{1.0, 10, 9}})
    for (Projection projection : {Projection::Orthographic, Projection::Perspective}) {
      const Camera camera = Camera::fit({{0, 0, 0}, {1, 1, 1}}, View::Iso, projection, 0, 0, 131, 77);
      const DensityMap reference = surface_density_reference(camera, 131, 77, p, m, kernel);
      for (int threads : {1, 2, 3})
        for (int tile : {1, 13, 64}) {
          parallel::set_thread_count(threads);
          const DensityMap map = surface_density(camera, 131, 77, p, m, kernel, tile);
          ASSERT_EQ(map.sigma, reference.sigma) << "threads " << threads << ", tile " << tile
                                                << ", adaptive " << kernel.neighbours;
        }
    }
  parallel::set_thread_count(saved);
}

TEST(SurfaceDensity, AdaptiveKernelsWidenWhereParticlesAreSparseAndKeepTheMass) {
  const double scale = 100;
  const Camera camera = front_camera(100, 100, scale);
  // A lone particle at the left, a crowd of 400 at the right.
  std::vector<Vec3d> p{{-0.5, 0, 0}};
  for (auto& q : test::random_cloud(400, 21, 0.45, 0.55)) p.push_back(q);
  const std::vector<double> m(p.size(), 1.0);
  const DensityKernel adaptive{1.0, 16, 12};
  const DensityMap map = surface_density(camera, 200, 200, p, m, adaptive);
  auto footprint = [&](int x0, int x1) {
    int n = 0;
    for (int y = 0; y < 200; ++y)
      for (int x = x0; x < x1; ++x) n += map.at(x, y) > 0;
    return n;
  };
  // The lone particle spreads to the largest radius: about π·12² pixels.
  EXPECT_NEAR(footprint(0, 100), kPiForTest * 144, 0.15 * kPiForTest * 144);
  EXPECT_NEAR(total(map) / (scale * scale), static_cast<double>(p.size()), 1e-9 * static_cast<double>(p.size()));
  // The crowd is sharper than with the largest kernel everywhere.
  const DensityMap wide = surface_density(camera, 200, 200, p, m, DensityKernel{12});
  EXPECT_GT(map.at(150, 50), wide.at(150, 50));  // the crowd lands around pixel (150, 50)
}

TEST(SurfaceDensity, LogColoursFollowTheMap) {
  DensityMap map{3, 1, {0.0, 10.0, 1000.0}};
  Image image(3, 1);
  draw_log_density(image, map, ColorMap::Inferno, 0.0, 4.0);  // log10 Σ from 0 to 4
  EXPECT_EQ(image.at(0, 0), colormap(ColorMap::Inferno, 0.0));   // empty: the bottom colour
  EXPECT_EQ(image.at(1, 0), colormap(ColorMap::Inferno, 0.25));  // log10 10 = 1
  EXPECT_EQ(image.at(2, 0), colormap(ColorMap::Inferno, 0.75));  // log10 1000 = 3
}

TEST(SurfaceDensity, RefusesBadArguments) {
  const std::vector<Vec3d> p{{0, 0, 0}};
  const std::vector<double> m{1.0}, none;
  const Camera camera = front_camera(5, 5, 1);
  EXPECT_THROW(surface_density(camera, 10, 10, p, none), std::invalid_argument);
  EXPECT_THROW(surface_density(camera, 10, 10, p, m, DensityKernel{0.5}), std::invalid_argument);
  EXPECT_THROW(surface_density(camera, 10, 10, p, m, DensityKernel{2.0, 10, 1.0}), std::invalid_argument);
  Image wrong(4, 4);
  EXPECT_THROW(draw_log_density(wrong, surface_density(camera, 10, 10, p, m), ColorMap::Inferno, 0, 1),
               std::invalid_argument);
}

}  // namespace
}  // namespace swirl::render
