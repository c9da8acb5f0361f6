// Every input the VTK reader fuzzer ever crashed on (tests/fuzz/regressions/vtp/)
// and every seed of its corpus (tests/fuzz/corpus/vtp/), replayed through
// read_vtp and read_pvd exactly as tests/fuzz/vtp_fuzz.cpp does: each file is
// read or refused with an IoError naming it; nothing else may escape.
#include <gtest/gtest.h>

#include <exception>
#include <filesystem>
#include <string>

#include "fuzz/io_replay.hpp"
#include "fuzz/replay_files.hpp"

namespace swirl::fuzz {
namespace {

const std::filesystem::path kFuzzDir = std::filesystem::path(SWIRL_SOURCE_DIR) / "tests" / "fuzz";

void replay_all(const std::filesystem::path& dir) {
  for (const auto& file : input_files(dir)) {
    SCOPED_TRACE(file.string());
    try {
      (void)replay_vtp(file);
      (void)replay_pvd(file);
    } catch (const std::exception& e) {
      ADD_FAILURE() << file.filename().string() << ": " << e.what();
    }
  }
}

TEST(VtpFuzzRegressions, KeptCrashesAreReadOrRefusedWithIoError) { replay_all(kFuzzDir / "regressions" / "vtp"); }

TEST(VtpFuzzRegressions, SeedCorpusIsReadOrRefusedWithIoError) {
  EXPECT_FALSE(input_files(kFuzzDir / "corpus" / "vtp").empty());
  replay_all(kFuzzDir / "corpus" / "vtp");
}

// The seeds swirl wrote are read back; the hand-made broken ones are refused.
TEST(VtpFuzzRegressions, SeedsAreReadOrRefusedAsExpected) {
  for (const auto& file : input_files(kFuzzDir / "corpus" / "vtp")) {
    const std::string name = file.filename().string();
    if (name.ends_with(".vtp")) {
      const bool broken = name.starts_with("truncated");
      EXPECT_EQ(replay_vtp(file).has_value(), broken) << name << ": " << replay_vtp(file).value_or("read");
    } else if (name.ends_with(".pvd")) {
      EXPECT_FALSE(replay_pvd(file).has_value()) << name << ": " << replay_pvd(file).value_or("");
    }
  }
}

}  // namespace
}  // namespace swirl::fuzz
