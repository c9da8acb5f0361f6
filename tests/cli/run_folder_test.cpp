// The run folder through `swirl run` (issue 17, findings 1-3): a folder that
// holds another run is refused unless --overwrite, which deletes only that
// run's files; checkpoints are chosen and pruned among the run's own; the
// user's files are never touched.
#include <gtest/gtest.h>

#include <fstream>

#include "cli_support.hpp"

namespace {

const std::string kGravity = std::string(SWIRL_SOURCE_DIR) +
                             "/examples/plummer.toml --set particles.0.count=200 --set output.interval=0.125";

class RunFolder : public Cli {
 protected:
  void put(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
  }
};

TEST_F(RunFolder, AFolderHoldingAnotherRunIsRefusedAndOverwriteDeletesOnlyThatRunsFiles) {
  const auto run = dir_ / "R";
  // The old run: more steps, so its checkpoints have the higher step numbers.
  ASSERT_EQ(swirl("run " + kGravity + " --steps 40 --checkpoint-every-steps 10 --out " + run.string()).status, 0);
  ASSERT_TRUE(fs::exists(run / "checkpoints" / "checkpoint_000000000040.swc"));
  // The user's own files in the folder.
  put(run / "notes.txt", "mine\n");
  put(run / "checkpoints" / "mine.swc", "not a checkpoint of any run\n");

  const auto refused = swirl("run " + kGravity + " --steps 10 --out " + run.string());
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("another"), std::string::npos) << refused.err;
  EXPECT_TRUE(fs::exists(run / "checkpoints" / "checkpoint_000000000040.swc"));  // nothing deleted

  const auto replaced = swirl("run " + kGravity + " --steps 12 --checkpoint-every-steps 4 --checkpoint-keep 2 --out " +
                              run.string() + " --overwrite");
  ASSERT_EQ(replaced.status, 0) << replaced.err;
  EXPECT_FALSE(fs::exists(run / "checkpoints" / "checkpoint_000000000040.swc"));  // the old run's, gone
  EXPECT_TRUE(fs::exists(run / "checkpoints" / "checkpoint_000000000012.swc"));   // the new run's newest two
  EXPECT_TRUE(fs::exists(run / "checkpoints" / "checkpoint_000000000008.swc"));
  EXPECT_FALSE(fs::exists(run / "checkpoints" / "checkpoint_000000000004.swc"));  // pruned: its own
  EXPECT_EQ(slurp(run / "notes.txt"), "mine\n");                                   // the user's, kept
  EXPECT_TRUE(fs::exists(run / "checkpoints" / "mine.swc"));

  // Resume continues the new run, from its own newest checkpoint.
  const auto resumed = swirl("run --resume " + run.string() + " --steps 2");
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("steps            2"), std::string::npos) << resumed.out;
  EXPECT_NE(resumed.out.find("t = 0.21875"), std::string::npos) << resumed.out;  // (12 + 2) · dt = 14 · 0.015625
}

TEST_F(RunFolder, OverwriteCannotGoWithResume) {
  const auto r = swirl("run --resume " + (dir_ / "R").string() + " --overwrite");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
}

}  // namespace

// A sibling of finding 1: the pictures of --render-every are the run's files
// too (listed in its manifest), so --overwrite deletes them with the frames,
// and a picture the run did not make is never drawn over.
TEST_F(RunFolder, RenderedPicturesAreTheRunsFiles) {
  const auto run = dir_ / "R";
  ASSERT_EQ(swirl("run " + kGravity + " --steps 16 --render-every 1 --out " + run.string()).status, 0);
  ASSERT_TRUE(fs::exists(run / "render" / "particles_000001.png"));
  EXPECT_NE(slurp(run / "manifest.txt").find("render/particles_000001.png"), std::string::npos);
  put(run / "render" / "mine.png", "the user's\n");
  const auto replaced = swirl("run " + kGravity + " --steps 8 --out " + run.string() + " --overwrite");
  ASSERT_EQ(replaced.status, 0) << replaced.err;
  EXPECT_FALSE(fs::exists(run / "render" / "particles_000001.png"));  // the old run's, gone
  EXPECT_EQ(slurp(run / "render" / "mine.png"), "the user's\n");
  // A folder with a picture of the user's where the run would draw: refused, the picture kept.
  const auto other = dir_ / "S";
  put(other / "render" / "particles_000000.png", "the user's\n");
  const auto r = swirl("run " + kGravity + " --steps 8 --render-every 1 --out " + other.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("particles_000000.png"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(other / "render" / "particles_000000.png"), "the user's\n");
}
