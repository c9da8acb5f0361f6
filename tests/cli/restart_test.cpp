// Runs that survive: checkpoint and bit-exact resume, signals, disk trouble.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "cli_support.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"

namespace {

const std::string kExamples = std::string(SWIRL_SOURCE_DIR) + "/examples/";
// A small dam break (a coarse block) and a small Plummer sphere.
const std::string kSph = kExamples + "dam_break.toml --set particles.0.spacing=0.03 --set output.interval=0.004";
const std::string kGravity = kExamples + "plummer.toml --set particles.0.count=400 --set output.interval=0.125";


class Restart : public Cli {};

TEST_F(Restart, SphResumedWithOtherThreadsEndsBitIdentical) {
  ASSERT_EQ(swirl("run " + kSph + " --steps 30 --threads 2 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + kSph + " --steps 12 --threads 2 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 1");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
}

// A Verlet skin keeps the particle order between sorts; the order's reference
// positions travel in the checkpoint, so the resumed run sorts exactly where
// the uninterrupted one does.
TEST_F(Restart, SphWithASkinResumesBitIdentically) {
  const std::string skin = kSph + " --set sph.grid.skin=0.008";
  const auto a = swirl("run " + skin + " --steps 30 --threads 2 --out " + (dir_ / "a").string());
  ASSERT_EQ(a.status, 0) << a.err;
  // The skin saved sorts (the summary's "sorts": one per evaluation without it).
  const auto at = a.out.find("sorts");
  ASSERT_NE(at, std::string::npos) << a.out;
  EXPECT_LT(std::stoi(a.out.substr(at + 5)), 31) << a.out;
  ASSERT_EQ(swirl("run " + skin + " --steps 13 --threads 1 --checkpoint-every-steps 13 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 17 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
}

// Boundary particles (walls and an obstacle of particles, DFSPH, adaptive
// steps): their kind and volume weights travel in the checkpoint, and the
// solver's "volumes done" flag in its state.
TEST_F(Restart, BoundaryParticlesResumeBitIdentically) {
  const std::string obstacle =
      kExamples + "dam_break_obstacle.toml --set particles.0.spacing=0.08 --set output.interval=0.01";
  ASSERT_EQ(swirl("run " + obstacle + " --steps 30 --threads 2 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + obstacle + " --steps 12 --threads 1 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
  // The frames hold the kind field, and the boundary particles are in their own (written once: they never move).
  EXPECT_FALSE(std::filesystem::exists(dir_ / "a" / "boundary_000001.vtp"));
  const auto frame = swirl::io::read_vtp(dir_ / "a" / "boundary_000000.vtp");
  ASSERT_TRUE(frame.point_data.count("kind"));
  EXPECT_EQ(frame.point_data.at("kind").type, "Int32");
  std::size_t boundary = 0;
  for (const auto k : frame.point_data.at("kind").template values<std::int32_t>()) boundary += k == 1 ? 1 : 0;
  EXPECT_GT(boundary, 1000u);
}

// A moving obstacle (the wave flume's piston): its particles' places are a
// function of t and of the scene, so the checkpoint needs nothing new, and the
// frames and probes.csv (the paddle's force and torque) resume byte-identical.
TEST_F(Restart, AMovingPistonResumesBitIdentically) {
  const std::string flume = kExamples + "wave_flume.toml --set particles.0.spacing=0.05 --set output.interval=0.02";
  ASSERT_EQ(swirl("run " + flume + " --steps 30 --threads 2 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + flume + " --steps 12 --threads 1 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
  EXPECT_NE(slurp(dir_ / "a" / "probes.csv").find("paddle_force_x"), std::string::npos);
}

// SPH and self-gravity in one run (one order for both, adaptive steps).
TEST_F(Restart, BothSolversResumeBitIdentically) {
  const std::string drop = std::string(SWIRL_SOURCE_DIR) +
                           "/examples/self_gravitating_drop.toml --set particles.0.count=600 "
                           "--set sph.smoothing_length=0.35 --set output.interval=0.02";
  ASSERT_EQ(swirl("run " + drop + " --steps 30 --threads 2 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + drop + " --steps 12 --threads 2 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 1");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
  const auto rows = slurp(dir_ / "a" / "diagnostics.csv");
  EXPECT_NE(rows.find("mean_density_error"), std::string::npos);  // both solvers' columns
  EXPECT_NE(rows.find("virial_ratio"), std::string::npos);
}

TEST_F(Restart, GravityResumedByTimeEndsBitIdentical) {
  ASSERT_EQ(swirl("run " + kGravity + " --until 0.5 --threads 1 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + kGravity + " --until 0.25 --threads 1 --checkpoint-every 0.1 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --until 0.5 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
}

// Block time steps: the bins are a function of the checkpointed state, so a
// resume on another thread count ends byte-identical; the frames carry each
// particle's bin.
TEST_F(Restart, BlockTimeStepsResumeBitIdentically) {
  const std::string block = kGravity + " --set simulation.time_steps='\"block\"' --set simulation.dt=0.0625 --set simulation.eta=0.2";
  const auto a = swirl("run " + block + " --until 0.5 --threads 1 --out " + (dir_ / "a").string());
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_NE(a.out.find("block_sub_steps"), std::string::npos) << a.out;
  ASSERT_EQ(swirl("run " + block + " --until 0.25 --threads 2 --checkpoint-every 0.125 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --until 0.5 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
  EXPECT_NE(slurp(dir_ / "a" / "particles_000004.vtp").find("time_bin"), std::string::npos);
}

// DFSPH: the warm starts are internal particle fields, so the checkpoint
// carries them; the grid and the factor α are recomputed at the restored
// positions. A resume on another thread count ends byte-identical (frames and
// the diagnostics' solver columns).
TEST_F(Restart, DfsphResumesBitIdenticallyWithItsWarmStarts) {
  const std::string dfsph = kSph + " --set sph.method='\"dfsph\"' --set simulation.dt=0.002";
  const auto a = swirl("run " + dfsph + " --steps 30 --threads 1 --out " + (dir_ / "a").string());
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_NE(a.out.find("dfsph_mean_density_iterations"), std::string::npos) << a.out;
  ASSERT_EQ(swirl("run " + dfsph + " --steps 12 --threads 2 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 1");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
  EXPECT_NE(slurp(dir_ / "a" / "diagnostics.csv").find("dfsph_density_iterations"), std::string::npos);
}

// DFSPH's XSPH filter and surface tension (examples/droplet.toml, coarse):
// no new state beyond the particles' fields (the normals and XSPH's Δv are
// recomputed from x, v, ρ), so a resume on another thread count ends
// byte-identical.
TEST_F(Restart, DropletWithXsphAndSurfaceTensionResumesBitIdentically) {
  const std::string drop = kExamples + "droplet.toml --set particles.0.spacing=0.01 --set output.interval=0.01";
  ASSERT_EQ(swirl("run " + drop + " --steps 30 --threads 1 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + drop + " --steps 12 --threads 2 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status, 0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 1");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
  // The terms act: without them the frames differ.
  const auto c = swirl("run " + drop + " --set sph.xsph=0 --set sph.surface_tension=0 --steps 30 --threads 1 --out " +
                       (dir_ / "c").string());
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(slurp(dir_ / "a" / "particles_000003.vtp"), slurp(dir_ / "c" / "particles_000003.vtp"));
}

TEST_F(Restart, ACorruptOrTruncatedCheckpointFallsBackToThePreviousOne) {
  ASSERT_EQ(swirl("run " + kSph + " --steps 30 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + kSph + " --steps 12 --checkpoint-every-steps 4 --checkpoint-keep 3 --out " + (dir_ / "b").string()).status, 0);
  const auto ckpt = dir_ / "b" / "checkpoints";
  // Keep 3: steps 4, 8 and 12. Truncate the newest, flip a byte in the next.
  const auto newest = ckpt / "checkpoint_000000000012.swc", middle = ckpt / "checkpoint_000000000008.swc";
  ASSERT_TRUE(fs::exists(ckpt / "checkpoint_000000000004.swc"));
  fs::resize_file(newest, fs::file_size(newest) / 2);
  std::string bytes = slurp(middle);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 1);
  std::ofstream(middle, std::ios::binary) << bytes;
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 26");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: skipping checkpoint: " + newest.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("checksum"), std::string::npos) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
}

TEST_F(Restart, ResumeRefusesWhatItCannotUse) {
  auto r = swirl("run --resume " + (dir_ / "nothing").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("scene.toml"), std::string::npos) << r.err;
  ASSERT_EQ(swirl("run " + kSph + " --steps 3 --out " + (dir_ / "b").string()).status, 0);
  r = swirl("run --resume " + (dir_ / "b").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no valid checkpoint"), std::string::npos) << r.err;
}

// A child run interrupted by SIGINT writes a checkpoint, says how to resume and
// exits 130; resumed, it ends as the uninterrupted run.
TEST_F(Restart, SigintCheckpointsAndResumeMatchesTheUninterruptedRun) {
  const std::string uninterrupted = (dir_ / "a").string(), interrupted = (dir_ / "b").string();
  ASSERT_EQ(swirl("run " + kGravity + " --steps 200 --out " + uninterrupted).status, 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string cmd = std::string(SWIRL_CLI) + " run " + kGravity + " --steps 200 --out " + interrupted + " >" +
                            (dir_ / "child.out").string() + " 2>" + (dir_ / "child.err").string();
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until the run is under way (its first frame exists), then interrupt it.
  for (int k = 0; k < 2000 && !fs::exists(dir_ / "b" / "particles_000001.vtp"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(child, SIGINT);
  int status = 0;
  waitpid(child, &status, 0);
  const std::string err = slurp(dir_ / "child.err");
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) GTEST_SKIP() << "the run finished before the signal arrived";
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 130) << err;
  EXPECT_NE(err.find("resume with: swirl run --resume " + interrupted), std::string::npos) << err;
  const auto r = swirl("run --resume " + interrupted + " --until 3.125");  // 200 steps of 1/64
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");
}

// A second signal exits at once; whatever was written before stays readable.
TEST_F(Restart, ASecondSignalExitsAtOnceLeavingWrittenFilesIntact) {
  const std::string out = (dir_ / "b").string();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string cmd = std::string(SWIRL_CLI) + " run " + kGravity + " --steps 100000 --out " + out +
                            " >/dev/null 2>" + (dir_ / "child.err").string();
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  for (int k = 0; k < 2000 && !fs::exists(dir_ / "b" / "particles_000002.vtp"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(child, SIGTERM);
  kill(child, SIGTERM);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << slurp(dir_ / "child.err");
  EXPECT_EQ(WEXITSTATUS(status), 143);
  const auto frames = swirl::io::read_pvd(dir_ / "b" / "particles.pvd");
  ASSERT_GE(frames.size(), 3u);
  for (const auto& f : frames) EXPECT_EQ(swirl::io::read_vtp(dir_ / "b" / f.file).num_points, 400u) << f.file;
}

// The disk fills up mid-run (a 600 KB tmpfs, frames of ~176 KB): the run stops
// with a message and exit status 1, and every frame written before is intact.
TEST_F(Restart, AFullDiskMidRunKeepsTheEarlierFrames) {
  const auto disk = dir_ / "disk";
  fs::create_directories(disk);
  if (std::system(("mount -t tmpfs -o size=600k tmpfs " + disk.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  const auto r = swirl("run " + kSph + " --steps 100 --checkpoint-every-steps 50 --out " + (disk / "run").string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("writing output failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  const auto frames = swirl::io::read_pvd(disk / "run" / "particles.pvd");
  EXPECT_GE(frames.size(), 1u);
  for (const auto& f : frames) EXPECT_GT(swirl::io::read_vtp(disk / "run" / f.file).num_points, 0u) << f.file;
  for (const auto& e : fs::directory_iterator(disk / "run"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "left-over " << e.path();
  EXPECT_EQ(std::system(("umount " + disk.string()).c_str()), 0);
}

// A disk already too full for the first frame is refused before running.
TEST_F(Restart, AFullDiskAtStartIsRefusedBeforeRunning) {
  const auto disk = dir_ / "disk";
  fs::create_directories(disk);
  if (std::system(("mount -t tmpfs -o size=200k tmpfs " + disk.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  std::system(("dd if=/dev/zero of=" + (disk / "filler").string() + " bs=1k count=150 2>/dev/null").c_str());
  const auto r = swirl("run " + kSph + " --steps 5 --out " + (disk / "run").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("the disk is full"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("steps per second"), std::string::npos) << r.out;
  EXPECT_EQ(std::system(("umount " + disk.string()).c_str()), 0);
}

// Hostile sizes are refused before anything is allocated or written.
TEST_F(Restart, ScenesBeyondMemoryOrSenseAreRefusedUpFront) {
  auto r = swirl("run " + kExamples + "random_box.toml --set particles=2000000000 --out " + (dir_ / "m").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("2000000000 particles need about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("GB of memory, more than the"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "m"));
  r = swirl("run " + kExamples + "random_box.toml --set sph.smoothing_length=1e300 --out " + (dir_ / "h").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("sph.smoothing_length: must be in (0, 1000000000], got 1e+300"), std::string::npos) << r.err;
  r = swirl("run " + kExamples + "random_box.toml --set simulation.dt=0 --out " + (dir_ / "h").string());
  EXPECT_NE(r.err.find("simulation.dt: must be > 0, got 0"), std::string::npos) << r.err;
  r = swirl("run " + kExamples + "falling_block.toml --set particles.0.mass=-1 --out " + (dir_ / "h").string());
  EXPECT_NE(r.err.find("particles[0].mass: must be > 0, got -1"), std::string::npos) << r.err;
  r = swirl("run " + kExamples + "falling_block.toml --set box.restitution=nan --out " + (dir_ / "h").string());
  EXPECT_NE(r.err.find("box.restitution: must be finite, got nan"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "h"));
  // Refused while its particles are built (a mass that overflows float): no output directory either.
  r = swirl("run " + std::string(SWIRL_SOURCE_DIR) + "/tests/fuzz/corpus/scene/limit_float_mass_1e300.toml --out " +
            (dir_ / "p").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("does not fit float precision"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "p"));
}

}  // namespace
