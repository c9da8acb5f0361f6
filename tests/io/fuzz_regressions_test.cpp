// Every input the io fuzzers ever crashed on (tests/fuzz/regressions/vtp/ and
// .../checkpoint/) and every seed of their corpora (tests/fuzz/corpus/...),
// replayed exactly as tests/fuzz/vtp_fuzz.cpp and checkpoint_fuzz.cpp do: each
// file is read or refused with an IoError naming it; nothing else may escape.
#include <gtest/gtest.h>

#include <cstdint>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz/checkpoint_replay.hpp"
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

// The kept VTP inputs are crafted corruptions of a file swirl wrote (see
// tests/fuzz/regressions/README.md): read_vtp must refuse every one.
TEST(VtpFuzzRegressions, KeptCraftedFilesAreRefused) {
  for (const auto& file : input_files(kFuzzDir / "regressions" / "vtp")) {
    const auto refusal = replay_vtp(file);
    EXPECT_TRUE(refusal.has_value()) << file.filename().string() << " was read";
  }
}

TEST(VtpFuzzRegressions, SeedCorpusIsReadOrRefusedWithIoError) {
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

void replay_all_checkpoints(const std::filesystem::path& dir) {
  for (const auto& file : input_files(dir)) {
    SCOPED_TRACE(file.string());
    try {
      replay_checkpoint(file_bytes(file));
      (void)replay_checkpoint_header(file);
    } catch (const std::exception& e) {
      ADD_FAILURE() << file.filename().string() << ": " << e.what();
    }
  }
}

TEST(CheckpointFuzzRegressions, KeptCrashesAreReadOrRefusedWithIoError) {
  replay_all_checkpoints(kFuzzDir / "regressions" / "checkpoint");
}

TEST(CheckpointFuzzRegressions, SeedCorpusIsReadOrRefusedWithIoError) {
  replay_all_checkpoints(kFuzzDir / "corpus" / "checkpoint");
}

// The seeds swirl wrote are read in their own precision only (those named
// *_v2 by the version-2 writer, still read); the truncated one, the one
// claiming a future format version and the version-1 one are refused.
TEST(CheckpointFuzzRegressions, SeedsAreReadOrRefusedAsExpected) {
  for (const auto& file : input_files(kFuzzDir / "corpus" / "checkpoint")) {
    const std::string name = file.filename().string();
    const std::string bytes = file_bytes(file);
    const bool broken = name.starts_with("truncated") || name.starts_with("version");
    const bool is_float = name.find("float") != std::string::npos;
    EXPECT_EQ(replay_checkpoint_as<float>(bytes).has_value(), broken || !is_float) << name;
    EXPECT_EQ(replay_checkpoint_as<double>(bytes).has_value(), broken || is_float) << name;
    if (broken) continue;
    ParticleSet<double> d;
    ParticleSet<float> f;
    io::CheckpointValues values;
    const io::CheckpointHeader h = is_float ? io::parse_checkpoint<float>(bytes, name, f, values)
                                            : io::parse_checkpoint<double>(bytes, name, d, values);
    const std::uint32_t expected = name.ends_with("_v2.ckp")   ? 2u
                                   : name.ends_with("_v3.ckp") ? 3u
                                                               : io::kCheckpointVersion;
    EXPECT_EQ(h.version, expected) << name;
  }
  const auto newer = replay_checkpoint_as<double>(file_bytes(kFuzzDir / "corpus" / "checkpoint" / "version5.ckp"));
  ASSERT_TRUE(newer.has_value());
  EXPECT_NE(newer->find("version 5 is not supported"), std::string::npos) << *newer;
  EXPECT_NE(newer->find("written by a newer swirl"), std::string::npos) << *newer;
  const auto v1 = replay_checkpoint_as<float>(file_bytes(kFuzzDir / "corpus" / "checkpoint" / "version1.ckp"));
  ASSERT_TRUE(v1.has_value());
  EXPECT_NE(v1->find("version 1 was written before the run state moved under owner prefixes"), std::string::npos)
      << *v1;
}

// The seed with an integer field carries it through the parser.
TEST(CheckpointFuzzRegressions, TheIntegerFieldSeedHoldsItsField) {
  ParticleSet<float> p;
  io::CheckpointValues values;
  (void)io::parse_checkpoint<float>(file_bytes(kFuzzDir / "corpus" / "checkpoint" / "sph_kind_float_3.ckp"), "seed", p,
                                    values);
  ASSERT_EQ(p.size(), 3u);
  const std::size_t kind = p.find_int_field("kind");
  ASSERT_NE(kind, ParticleSet<float>::npos);
  EXPECT_EQ(std::vector<std::int32_t>(p.int_field(kind).begin(), p.int_field(kind).end()),
            (std::vector<std::int32_t>{1, -7, 2147483647}));
}

}  // namespace
}  // namespace swirl::fuzz
