// run_scene: frames at output times, and a blow-up keeps the last good output.
#include "swirl/sim/run.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"

namespace fs = std::filesystem;

namespace {

swirl::scene::Scene small_scene(swirl::scene::Precision precision) {
  swirl::scene::Scene s;
  s.file = "test";
  s.precision = precision;
  s.dt = 0.03;
  s.end_time = 0.5;
  s.block_size = 4;
  s.box = {{0, 0, 0}, {1, 1, 1}};
  s.output_interval = 0.1;
  swirl::scene::ListSource list;
  list.positions = {{0.5, 0.5, 0.5}, {0.2, 0.3, 0.9}, {0.7, 0.1, 0.4}};
  list.masses = {1, 2, 3};
  s.sources.push_back(list);
  return s;
}

class RunScene : public ::testing::TestWithParam<swirl::scene::Precision> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swirl_run_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_P(RunScene, FramesAreWrittenAtTheFirstStepPastEachOutputTime) {
  auto scene = small_scene(GetParam());
  swirl::sim::RunOptions options;
  options.out_dir = dir_;
  const auto summary = swirl::sim::run_scene(scene, options);
  EXPECT_TRUE(summary.error.empty()) << summary.error;
  EXPECT_EQ(summary.steps, 17u);  // ceil(0.5 / 0.03)
  const auto entries = swirl::io::read_pvd(dir_ / "particles.pvd");
  // t = 0, then the first step at or past 0.1, 0.2, 0.3, 0.4, 0.5: 0.12, 0.21, 0.30, 0.42, and the end 0.51.
  const std::vector<double> expected{0.0, 0.12, 0.21, 0.30, 0.42, 0.51};
  ASSERT_EQ(entries.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(entries[k].time, expected[k], 1e-12) << k;
  EXPECT_EQ(summary.frames, expected.size());
  const auto last = swirl::io::read_vtp(dir_ / entries.back().file);
  EXPECT_EQ(last.num_points, 3u);
}

TEST_P(RunScene, ABlowUpStopsTheRunAndKeepsTheFramesWrittenBefore) {
  auto scene = small_scene(GetParam());
  // Absurd gravity and step: positions overflow to infinity in the first step
  // (the gravity itself is finite in float: a non-finite initial force would
  // stop start(), before frame 0).
  scene.gravity = {0, 0, -1e30};
  scene.dt = 1e200;
  scene.end_time.reset();
  scene.steps = 50;
  scene.output_interval = 0;
  swirl::sim::RunOptions options;
  options.out_dir = dir_;
  const auto summary = swirl::sim::run_scene(scene, options);
  EXPECT_NE(summary.error.find("non-finite"), std::string::npos) << summary.error;
  EXPECT_LT(summary.steps, 50u);
  ASSERT_EQ(summary.frames, 1u);
  const auto entries = swirl::io::read_pvd(dir_ / "particles.pvd");
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(swirl::io::read_vtp(dir_ / entries[0].file).num_points, 3u);  // the initial frame, intact
}

INSTANTIATE_TEST_SUITE_P(Precisions, RunScene,
                         ::testing::Values(swirl::scene::Precision::Float, swirl::scene::Precision::Double));

}  // namespace
