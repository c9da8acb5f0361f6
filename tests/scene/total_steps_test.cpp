// Scene::total_steps: steps as given, or end_time / dt rounded up unless
// end_time is a whole number of steps up to rounding.
#include <gtest/gtest.h>

#include <limits>

#include "scene/scene_test_util.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

std::uint64_t steps_for(double end_time, double dt) {
  Scene s;
  s.dt = dt;
  s.end_time = end_time;
  return s.total_steps();
}

TEST(TotalSteps, StepsAreTakenAsGiven) {
  Scene s;
  s.dt = 0.1;
  s.steps = 17;
  EXPECT_EQ(s.total_steps(), 17u);
}

TEST(TotalSteps, EndTimeThatIsAWholeNumberOfSteps) {
  EXPECT_EQ(steps_for(1.5, 1e-3), 1500u);
  EXPECT_EQ(steps_for(1.0, 0.25), 4u);
}

// end_time / dt lands just below (0.3 / 0.1) or just above (0.9 / 0.03) the
// whole number; neither may gain or lose a step.
TEST(TotalSteps, EndTimeWithRoundingTrouble) {
  ASSERT_LT(0.3 / 0.1, 3.0);
  EXPECT_EQ(steps_for(0.3, 0.1), 3u);
  EXPECT_EQ(steps_for(0.7, 0.1), 7u);
  ASSERT_GT(0.9 / 0.03, 30.0);
  EXPECT_EQ(steps_for(0.9, 0.03), 30u);
  EXPECT_EQ(steps_for(2.3, 0.0001), 23000u);
}

TEST(TotalSteps, EndTimeBetweenStepsRoundsUp) {
  EXPECT_EQ(steps_for(1.05, 0.1), 11u);
  EXPECT_EQ(steps_for(1.0 + 1e-6, 0.1), 11u);
  EXPECT_EQ(steps_for(0.01, 1.0), 1u);
  EXPECT_EQ(steps_for(1e-12, 1.0), 1u) << "a positive end_time takes at least one step";
}

TEST(TotalSteps, FromAFile) {
  EXPECT_EQ(parse_scene(test::kFullScene, "s.toml").total_steps(), 500u);
  EXPECT_EQ(parse_scene(test::kMinimalScene, "s.toml").total_steps(), 10u);
  const std::vector<std::string> tricky{"simulation.dt=0.03", "simulation.end_time=0.9"};
  EXPECT_EQ(parse_scene(test::kFullScene, "s.toml", tricky).total_steps(), 30u);
}

TEST(TotalSteps, UnsetOrNonsenseIsZeroOrSaturates) {
  EXPECT_EQ(Scene{}.total_steps(), 0u);
  EXPECT_EQ(steps_for(1.0, std::numeric_limits<double>::denorm_min()), std::numeric_limits<std::uint64_t>::max());
}

}  // namespace
}  // namespace swirl::scene
