// Runs that cannot hurt the user (issue 17), the CLI's part: one test per
// finding (numbered as in the issue), each also covering the finding's siblings.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
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

// Finding 4: zero softening and a close pair: a warning before the first
// step, then the energy-error guard stops the run (exit 1) with the error
// logged; the threshold is a scene key (0 turns the check off).
TEST_F(Safety, Finding4_AnEnergyErrorPastTheLimitStopsTheRun) {
  const auto scene = write_scene("close.toml", R"([simulation]
dt = 0.001
end_time = 0.05
[nbody]
softening = 0.0
opening = 0.0
[output]
interval = 0.01
[[particles]]
kind = "list"
positions = [[0.0, 0.0, 0.0], [1e-6, 0.0, 0.0], [1.0, 0.0, 0.0]]
velocities = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
mass = 1.0
)");
  const auto r = swirl("run " + scene.string() + " --out " + (dir_ / "a").string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("warning: " + scene.string() + ": nbody.softening = 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("blow-up: the relative energy error is"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("simulation.max_energy_error = 0.1"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("swirl run: STOPPED"), std::string::npos) << r.out;
  const auto rows = csv_rows(dir_ / "a" / "diagnostics.csv");
  ASSERT_GE(rows.size(), 3u);  // header, t = 0, the row that failed
  EXPECT_GT(std::abs(std::stod(rows.back()[column(rows[0], "relative_energy_error")])), 0.1);
  // Turned off, the same run ends "done" (the warning stays).
  const auto off = swirl("run " + scene.string() + " --set simulation.max_energy_error=0 --out " + (dir_ / "b").string());
  EXPECT_EQ(off.status, 0) << off.err;
  EXPECT_NE(off.err.find("nothing stops a run whose energy is ruined"), std::string::npos) << off.err;
  // With softening: no warning, and the run conserves energy well within the limit.
  const auto soft = swirl("run " + scene.string() + " --set nbody.softening=0.05 --out " + (dir_ / "c").string());
  EXPECT_EQ(soft.status, 0) << soft.err;
  EXPECT_EQ(soft.err.find("warning"), std::string::npos) << soft.err;
  // Walls that take energy out: no energy check (and no column) at all.
  const auto walls = swirl("run " + scene.string() + " --set simulation.max_energy_error=1e-12 --out " +
                           (dir_ / "d").string() + " --set 'box.min=[-2.0,-2.0,-2.0]' --set 'box.max=[2.0,2.0,2.0]'" +
                           " --set box.restitution=0.5 --set nbody.softening=0.05");
  EXPECT_EQ(walls.status, 0) << walls.err;
  EXPECT_EQ(slurp(dir_ / "d" / "diagnostics.csv").find("relative_energy_error"), std::string::npos);
}

// Finding 5, on resume: --steps counts from the checkpoint, and a count that
// passes 2^53 from there, or an --until already passed, is refused.
TEST_F(Safety, Finding5_ResumeRefusesStepCountsItCannotHonour) {
  const auto run = dir_ / "run";
  ASSERT_EQ(swirl("run " + scene() + " --out " + run.string() + " --steps 10 --checkpoint-every-steps 5").status, 0);
  const std::string resume = "run --resume " + run.string();
  expect_refused(resume + " --steps 9007199254740990", "--steps 9007199254740990: from step 10");
  expect_refused(resume + " --until 0.05", "--until 0.05: the run is already at t = 0.1");
  const auto r = swirl(resume + " --steps 3");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("steps            3 (t = 0.13"), std::string::npos) << r.out;
}

// Finding 6: the run folder remembers where the run ends (--steps, --until),
// so the resume hint needs no flags; a run already at its end is refused
// (nothing run, no extra frame); progress never passes 100 %.
TEST_F(Safety, Finding6_AResumeEndsWhereTheRunWasToldToEnd) {
  const auto run = dir_ / "run";
  ASSERT_EQ(swirl("run " + scene() + " --out " + run.string() + " --steps 20 --checkpoint-every-steps 5 --checkpoint-keep 4")
                .status,
            0);
  const auto frames = swirl::io::read_pvd(run / "particles.pvd").size();
  // Nothing left to do: refused, nothing written.
  auto r = swirl("run --resume " + run.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("the run already reached the end it was given (step 20"), std::string::npos) << r.err;
  EXPECT_EQ(swirl::io::read_pvd(run / "particles.pvd").size(), frames);
  // As after a stop at step 10: the resume goes to step 20 (the scene's end is step 24).
  fs::remove(run / "checkpoints" / "checkpoint_000000000020.swc");
  fs::remove(run / "checkpoints" / "checkpoint_000000000015.swc");
  r = swirl("run --resume " + run.string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("steps            10 (t = 0.2"), std::string::npos) << r.out;
  for (auto at = r.err.find("progress"); at != std::string::npos; at = r.err.find("progress", at + 1)) {
    const int percent = std::stoi(r.err.substr(at + 8, 5));
    EXPECT_LE(percent, 100) << r.err;
  }
  EXPECT_NE(r.err.find("step 20/20"), std::string::npos) << r.err;
  // --until is remembered too (time 0.15 = step 15).
  const auto timed = dir_ / "timed";
  ASSERT_EQ(swirl("run " + scene() + " --out " + timed.string() + " --until 0.15 --checkpoint-every-steps 5 --checkpoint-keep 4")
                .status,
            0);
  fs::remove(timed / "checkpoints" / "checkpoint_000000000015.swc");
  r = swirl("run --resume " + timed.string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("steps            5 (t = 0.15"), std::string::npos) << r.out;
}

// Finding 7: --on-blowup=warn goes on, but a run that went past failed checks
// ends with status 1 and a summary of what failed (also in --summary-json).
TEST_F(Safety, Finding7_WarnGoesOnButEndsWithStatus1AndWhatFailed) {
  const std::string dam = std::string(SWIRL_SOURCE_DIR) + "/examples/dam_break.toml";
  const auto json = dir_ / "summary.json";
  const auto r = swirl("run " + dam + " --set simulation.dt=5e-3 --set simulation.end_time=0.02 --on-blowup=warn --out " +
                       (dir_ / "a").string() + " --summary-json " + json.string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.out.find("swirl run: FINISHED, BUT CHECKS FAILED"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("went on past failed checks"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4 steps failed the 'time-step condition' check"), std::string::npos) << r.err;
  const std::string summary = slurp(json);
  const auto list = summary.find("\"failed_checks\": [\"");
  ASSERT_NE(list, std::string::npos) << summary;
  EXPECT_LT(list, summary.find("4 steps failed the 'time-step condition' check")) << summary;
}

// Finding 7, the gravity half: forces that are not finite in the initial state
// (two particles 1e-155 apart, no softening: r³ underflows) stop before frame 0 is written,
// and the message does not blame the time step.
TEST_F(Safety, Finding7_InitialForcesThatAreNotFiniteStopBeforeFrame0) {
  const auto scene = write_scene("same.toml", R"([simulation]
dt = 0.001
steps = 5
[nbody]
softening = 0.0
[[particles]]
kind = "list"
positions = [[0.0, 0.0, 0.0], [1e-155, 0.0, 0.0], [1.0, 0.0, 0.0]]
velocities = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
mass = 1.0
)");
  const auto r = swirl("run " + scene.string() + " --out " + (dir_ / "a").string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("before the first step: blow-up: the forces of the initial state are not finite"),
            std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("time step"), r.err.find("no time step is involved") + 3) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "a" / "particles_000000.vtp"));
}

// Finding 9: the sizes a scene sets (hash buckets, a smoothing length that
// makes every particle a neighbour, a dense cell table) are in the memory
// estimate or the validation: refused at once with status 2, not minutes of
// allocation, and before the run's folder is made.
TEST_F(Safety, Finding9_EverySizeASceneSetsIsInTheMemoryEstimate) {
  const auto scene = write_scene("sph.toml", R"([simulation]
dt = 1e-4
steps = 1
[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]
[sph]
smoothing_length = 0.05
[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [0.5, 0.5, 0.5]
spacing = 0.02
)");
  ASSERT_EQ(swirl("run " + scene.string() + " --out " + (dir_ / "fits").string()).status, 0);
  const std::string run = "run " + scene.string() + " --out " + (dir_ / "o").string();
  for (const std::string set : {"--set 'sph.neighbour_search=\"hash\"' --set sph.hash.buckets=4000000000",
                                 // h = 5 over 125000 particles: every particle a neighbour of every other.
                                 "--set sph.smoothing_length=5 --set particles.0.spacing=0.01"}) {
    const auto r = swirl_bounded(run + " " + set);
    EXPECT_EQ(r.status, 2) << set << "\n" << r.err;
    EXPECT_NE(r.err.find("GB of memory"), std::string::npos) << set << "\n" << r.err;
  }
  // A dense cell table past 2^31 entries is a scene error, before the folder is made.
  const auto r = swirl(run + " --set 'sph.grid.table=\"dense\"' --set sph.smoothing_length=1e-4");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sph.grid.table: a dense cell table over the box"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

// Finding 14: a particle thrown out of the box by a huge force (speed 0, the
// displacement from ½·a·dt²) is reported with what moved it, and no "at most 0".
TEST_F(Safety, Finding14_TheLeftTheBoxMessageNamesWhatMovedTheParticle) {
  const std::string dam = std::string(SWIRL_SOURCE_DIR) + "/examples/dam_break.toml";
  const auto r = swirl("run " + dam + " --set sph.sound_speed=1e12 --steps 3 --out " + (dir_ / "o").string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("left the box"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("speed 0, acceleration"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("|v|·dt = 0"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("at most 0)"), std::string::npos) << r.err;
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
