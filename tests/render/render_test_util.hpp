// Shared pieces of the render tests: a temporary folder, explicit cameras and
// random particle clouds.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "swirl/render/camera.hpp"

namespace swirl::render::test {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("swirl_render_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

// Front view, orthographic: world (x, z) lands at (cx + s·x, cy − s·z).
inline Camera front_camera(double cx, double cy, double s) {
  Camera c;
  c.projection = Projection::Orthographic;
  view_axes(View::Front, c.forward, c.right, c.up);
  c.target = {0, 0, 0};
  c.centre_x = cx;
  c.centre_y = cy;
  c.scale = s;
  return c;
}

inline std::vector<Vec3d> random_cloud(std::size_t n, std::uint64_t seed, double lo = 0, double hi = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<Vec3d> p(n);
  for (auto& v : p) v = {u(rng), u(rng), u(rng)};
  return p;
}

inline std::vector<double> random_values(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

}  // namespace swirl::render::test
