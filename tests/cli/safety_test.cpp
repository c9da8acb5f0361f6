// Runs that cannot hurt the user (issue 17), the CLI's part: one test per
// finding (numbered as in the issue), each also covering the finding's siblings.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>
#include <vector>

#include "cli_support.hpp"
#include "swirl/io/pvd.hpp"

namespace {

// 24 steps of 0.01 s, frames every 0.06 s: five frames.
const char* kScene = R"([simulation]
dt = 0.01
end_time = 0.24
[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]
[output]
interval = 0.06
[[particles]]
kind = "lattice"
min = [0.3, 0.3, 0.5]
max = [0.7, 0.7, 0.9]
spacing = 0.1
mass = 0.001
)";

class Safety : public Cli {
 protected:
  // A command that must end by itself: a hang (the bug) fails as status 124
  // instead of stalling the test suite.
  Result swirl_bounded(const std::string& args) { return swirl(args, "timeout 60 "); }
  std::string scene() { return write_scene("s.toml", kScene).string(); }
  // A usage error: status 2, the flag named, nothing run.
  void expect_refused(const std::string& args, const std::string& flag) {
    const auto r = swirl(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(flag), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.out.find("steps per second"), std::string::npos) << args;
  }
};

// Finding 5: step counts and intervals that cannot be honoured are refused.
TEST_F(Safety, Finding5_StepCountsThatOverflowAreRefused) {
  const std::string run = "run " + scene() + " --out " + (dir_ / "o").string();
  expect_refused(run + " --until 1e20", "--until");
  expect_refused(run + " --until nan", "--until");
  expect_refused(run + " --until inf", "--until");
  expect_refused(run + " --until -1", "--until");
  expect_refused(run + " --steps 99999999999999999999999", "--steps");
  expect_refused(run + " --steps 18446744073709551615", "--steps");
  expect_refused(run + " --steps -1", "--steps");
  expect_refused(run + " --steps 1e3", "--steps");
  expect_refused(run + " --checkpoint-every nan", "--checkpoint-every");
  expect_refused(run + " --checkpoint-every 0", "--checkpoint-every");
  expect_refused(run + " --checkpoint-every inf", "--checkpoint-every");
  expect_refused(run + " --checkpoint-every-steps 99999999999999999999", "--checkpoint-every-steps");
  expect_refused(run + " --checkpoint-keep 0", "--checkpoint-keep");
  expect_refused(run + " --render-every 99999999999999999999", "--render-every");
  expect_refused("hash-stats " + scene() + " --steps 99999999999999999999", "--steps");
  expect_refused("bench bh-table --quick --opening nan", "--opening");
  expect_refused("bench sph-table --quick --sizes 99999999999999999999", "--sizes");
  EXPECT_FALSE(fs::exists(dir_ / "o"));
  // The largest count is still accepted: --until's bound is the step count, not T.
  const auto r = swirl(run + " --until 0.05");
  EXPECT_EQ(r.status, 0) << r.err;
}

// Finding 8: a thread count OpenMP cannot start is refused (flags) or lowered
// (OMP_NUM_THREADS), never a crash inside the runtime.
TEST_F(Safety, Finding8_HugeThreadCountsAreCappedNotACrash) {
  const std::string run = "run " + scene() + " --out " + (dir_ / "o").string();
  expect_refused(run + " --threads 100000", "--threads");
  expect_refused("render " + dir_.string() + " --threads 100000", "--threads");
  expect_refused("hash-stats " + scene() + " --threads 100000", "--threads");
  expect_refused("bench bh-table --quick --threads 1,100000", "--threads");
  const auto r = swirl(run, "OMP_NUM_THREADS=100000 ");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: OpenMP was asked for 100000 threads"), std::string::npos) << r.err;
}

// Finding 10: a FIFO given as a scene, a checkpoint, a frame or a series is
// refused at once (the readers used to wait for a writer forever).
TEST_F(Safety, Finding10_AFifoIsRefusedByEveryReader) {
  const auto fifo = dir_ / "fifo.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& command : {"run " + fifo.string() + " --out " + (dir_ / "o").string(), "hash-stats " + fifo.string()}) {
    const auto r = swirl_bounded(command);
    EXPECT_EQ(r.status, 2) << command << r.err;
    EXPECT_NE(r.err.find("is a FIFO"), std::string::npos) << r.err;
  }

  // A checkpoint that is a FIFO: skipped with a warning, so nothing to resume from.
  const auto run = dir_ / "run";
  ASSERT_EQ(swirl("run " + scene() + " --out " + run.string() + " --steps 10 --checkpoint-every-steps 5").status, 0);
  for (const auto& e : fs::directory_iterator(run / "checkpoints")) fs::remove(e.path());
  ASSERT_EQ(::mkfifo((run / "checkpoints" / "checkpoint_000000000010.swc").c_str(), 0600), 0);
  auto r = swirl_bounded("run --resume " + run.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("checkpoint_000000000010.swc: is a FIFO"), std::string::npos) << r.err;

  // A frame named in the .pvd that is a FIFO is not read (a missing frame);
  // a .pvd that is a FIFO is refused.
  ASSERT_EQ(swirl("run " + scene() + " --out " + (dir_ / "r2").string()).status, 0);
  fs::remove(dir_ / "r2" / "particles_000001.vtp");
  ASSERT_EQ(::mkfifo((dir_ / "r2" / "particles_000001.vtp").c_str(), 0600), 0);
  r = swirl_bounded("render " + (dir_ / "r2").string() + " --all --size 96x96");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("particles_000001.vtp"), std::string::npos) << r.err;
  fs::remove(dir_ / "r2" / "particles.pvd");
  ASSERT_EQ(::mkfifo((dir_ / "r2" / "particles.pvd").c_str(), 0600), 0);
  r = swirl_bounded("render " + (dir_ / "r2").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("particles.pvd: is a FIFO"), std::string::npos) << r.err;
}

// Finding 12: every usage error exits 2 (not CLI11's 104..114) with a readable message.
TEST_F(Safety, Finding12_EveryUsageErrorExits2) {
  const std::string s = scene();
  for (const std::string& args : std::vector<std::string>{"", "bogus", "run " + s + " --bogus", "run " + s + " --threads abc", "run " + s + " --steps 1 --until 1",
        "run " + s + " --on-blowup maybe", "render", "render x --frame 1 --all", "run " + s + " --threads",
        "bench", "bench nothing", "info extra"}) {
    const auto r = swirl(args);
    EXPECT_EQ(r.status, 2) << "swirl " << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
  }
  const auto r = swirl("run " + s + " --threads 0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--threads: 0 is out of range: give 1 to"), std::string::npos) << r.err;
  EXPECT_LT(r.err.size(), 300u) << "no 309-digit limits: " << r.err;
  EXPECT_EQ(swirl("--help").status, 0);
  EXPECT_EQ(swirl("--version").status, 0);
  EXPECT_EQ(swirl("run --help").status, 0);
}

// Finding 13: every output path is checked before the first step.
TEST_F(Safety, Finding13_OutputPathsAreCheckedBeforeTheRun) {
  const std::string run = "run " + scene() + " --out " + (dir_ / "o").string();
  expect_refused(run + " --summary-json /nonexistent/dir/x.json", "/nonexistent/dir");
  expect_refused(run + " --summary-json " + dir_.string(), "not a regular file");
  EXPECT_FALSE(fs::exists(dir_ / "o")) << "refused before the run made its folder";
  // An output that is the scene being read, or a file the run itself writes.
  expect_refused(run + " --summary-json " + (dir_ / "s.toml").string(), "is the scene file");
  expect_refused(run + " --summary-json " + (dir_ / "o" / "particles.pvd").string(), "the run writes that file");
  fs::create_directories(dir_ / "d");
  const auto mine = write_scene("d/scene.toml", kScene);
  expect_refused("run " + mine.string() + " --out " + (dir_ / "d").string(), "is the scene file");
  EXPECT_EQ(slurp(mine), kScene) << "the user's scene is untouched";
  // The benchmark suites check --out before measuring.
  std::ofstream(dir_ / "file") << "x";
  expect_refused("bench bh-table --quick --out " + (dir_ / "file" / "sub").string(), "file/sub");
}

// Finding 15: render --all draws every frame there is, names the missing ones
// and exits 1.
TEST_F(Safety, Finding15_RenderAllDrawsTheFramesThereAreAndNamesTheMissing) {
  const auto run = dir_ / "run";
  ASSERT_EQ(swirl("run " + scene() + " --out " + run.string()).status, 0);
  const auto frames = swirl::io::read_pvd(run / "particles.pvd");
  ASSERT_EQ(frames.size(), 5u);
  fs::remove(run / frames[0].file);
  fs::remove(run / frames[2].file);
  const auto r = swirl("render " + run.string() + " --all --size 96x96");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("2 frames are missing"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(frames[0].file + ", " + frames[2].file), std::string::npos) << r.err;
  for (std::size_t k : {1u, 3u, 4u})
    EXPECT_TRUE(fs::exists(run / "render" / fs::path(frames[k].file).replace_extension(".png"))) << k;
  // Every frame missing: nothing to draw, a usage error.
  for (std::size_t k : {1u, 3u, 4u}) fs::remove(run / frames[k].file);
  EXPECT_EQ(swirl("render " + run.string() + " --all --size 96x96").status, 2);
}

// Finding 16: the demo installs and builds only the tool (no test packages,
// no test suite): what `make demo` would run, without running it (and without
// the flags of a `make test` this may run under).
TEST_F(Safety, Finding16_TheDemoBuildsOnlyTheTool) {
  const auto plan = dir_ / "plan.txt";
  ASSERT_EQ(std::system(("env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -n -C " + std::string(SWIRL_SOURCE_DIR) + " demo >" + plan.string() + " 2>&1").c_str()), 0)
      << slurp(plan);
  const std::string text = slurp(plan);
  for (const char* test_only : {"libgtest-dev", "libbenchmark-dev", "python3-matplotlib", "ctest"})
    EXPECT_EQ(text.find(test_only), std::string::npos) << test_only << " in:\n" << text;
  EXPECT_NE(text.find("--preset demo"), std::string::npos) << text;
  EXPECT_NE(text.find("--target swirl_cli"), std::string::npos) << text;
  const std::string presets = slurp(fs::path(SWIRL_SOURCE_DIR) / "CMakePresets.json");
  const auto demo = presets.find("\"name\": \"demo\"");
  ASSERT_NE(demo, std::string::npos);
  EXPECT_NE(presets.find("\"SWIRL_BUILD_TESTS\": \"OFF\"", demo), std::string::npos);
}

}  // namespace
