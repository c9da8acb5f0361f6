// Every input the scene fuzzer ever crashed on (tests/fuzz/regressions/scene/)
// and every seed of its corpus (tests/fuzz/corpus/scene/), replayed through
// parse_scene exactly as tests/fuzz/scene_fuzz.cpp does: each is accepted or
// refused with a one-line SceneError naming the file; nothing else may escape.
#include <gtest/gtest.h>

#include <exception>
#include <filesystem>
#include <string>

#include "fuzz/replay_files.hpp"
#include "fuzz/scene_replay.hpp"

namespace swirl::fuzz {
namespace {

const std::filesystem::path kFuzzDir = std::filesystem::path(SWIRL_SOURCE_DIR) / "tests" / "fuzz";

void replay_all(const std::filesystem::path& dir, bool strict) {
  for (const auto& file : input_files(dir)) {
    SCOPED_TRACE(file.string());
    try {
      (void)replay_scene(file_bytes(file), strict);
    } catch (const std::exception& e) {
      ADD_FAILURE() << file.filename().string() << ": " << e.what();
    }
  }
}

TEST(SceneFuzzRegressions, KeptCrashesAreAcceptedOrRefusedWithSceneError) {
  replay_all(kFuzzDir / "regressions" / "scene", false);
}

TEST(SceneFuzzRegressions, SeedCorpusIsAcceptedOrRefusedWithSceneError) {
  replay_all(kFuzzDir / "corpus" / "scene", false);
}

// Seeds named bad_* exist to be refused, the others to be accepted.
TEST(SceneFuzzRegressions, SeedsAreAcceptedOrRefusedAsNamed) {
  for (const auto& file : input_files(kFuzzDir / "corpus" / "scene")) {
    const std::string name = file.filename().string();
    if (name.starts_with("limit_")) continue;  // see StrictLimits below
    const auto error = replay_scene(file_bytes(file));
    if (name.starts_with("bad_") || name == "empty.toml")
      EXPECT_TRUE(error.has_value()) << name << " was accepted";
    else
      EXPECT_FALSE(error.has_value()) << name << ": " << error.value_or("");
  }
}

// Strict replay: an accepted scene must also make finite particles with
// positive masses. Fails until absurd values (h = 1e300, a box beyond the
// float range) are refused by validation; enable with that fix.
TEST(SceneFuzzRegressions, StrictLimits) {
  replay_all(kFuzzDir / "regressions" / "scene", true);
  replay_all(kFuzzDir / "corpus" / "scene", true);
}

}  // namespace
}  // namespace swirl::fuzz
