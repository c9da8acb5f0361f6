// The scalar twins are reachable from a scene: sph.grid.simd = false and
// nbody.simd = false run the reference kernels, whose accelerations agree with
// the SIMD ones to rounding (core/kernel_path.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"

namespace {

using namespace swirl;

// The accelerations of the initial state, by particle id.
std::vector<double> initial_accelerations(const std::string& text) {
  const scene::Scene s = scene::parse_scene(text, "scene.toml");
  Simulation<double> sim = sim::build_simulation<double>(s);
  sim.start();
  const auto& p = sim.particles();
  std::vector<double> a(3 * p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int axis = 0; axis < 3; ++axis) a[3 * p.id[i] + static_cast<std::size_t>(axis)] = p.acceleration[axis][i];
  return a;
}

void expect_close(const std::vector<double>& simd, const std::vector<double>& scalar) {
  ASSERT_EQ(simd.size(), scalar.size());
  double scale = 0;
  for (const double v : simd) scale = std::max(scale, std::abs(v));
  ASSERT_GT(scale, 0);
  for (std::size_t k = 0; k < simd.size(); ++k) EXPECT_NEAR(simd[k], scalar[k], 1e-10 * scale) << k;
  // The key reached the kernels: the twin sums in another order, so some bits differ.
  EXPECT_NE(simd, scalar);
}

TEST(KernelPath, NbodySimdFalseRunsTheScalarTwinOfTheTreeKernels) {
  const std::string scene = R"([simulation]
dt = 0.01
steps = 1
[nbody]
opening = 0.5
[[particles]]
kind = "plummer"
count = 500
seed = 3
)";
  const std::string scalar = std::string(scene).replace(scene.find("opening = 0.5"), 13, "opening = 0.5\nsimd = false");
  expect_close(initial_accelerations(scene), initial_accelerations(scalar));
}

TEST(KernelPath, SphGridSimdFalseRunsTheScalarTwinOfTheGridPasses) {
  const std::string scene = R"([simulation]
dt = 1e-4
steps = 1
[box]
min = [0.0, 0.0, 0.0]
max = [0.4, 0.4, 0.4]
[sph]
smoothing_length = 0.045
[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [0.2, 0.3, 0.2]
spacing = 0.02
)";
  const std::string scalar = std::string(scene).replace(scene.find("smoothing_length = 0.045"), 24,
                                                        "smoothing_length = 0.045\ngrid.simd = false");
  expect_close(initial_accelerations(scene), initial_accelerations(scalar));
}

}  // namespace
