// swirl render and swirl run --render-every, as a user runs them.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "cli/cli_support.hpp"

namespace {

// A quick scene: a small block falling in a box, frames at steps 0, 10, 20, 30.
constexpr const char* kScene = R"([simulation]
dt = 0.001
steps = 30

[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]

[output]
interval = 0.01

[[particles]]
kind = "lattice"
min = [0.3, 0.3, 0.5]
max = [0.7, 0.7, 0.9]
spacing = 0.05
mass = 0.001
)";

// PNG signature and IHDR width/height, without a PNG library.
bool is_png(const std::string& bytes, int width, int height) {
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return false;
  auto be32 = [&](std::size_t at) {
    long v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = v * 256 + static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  return be32(16) == width && be32(20) == height;
}

class Render : public Cli {
 protected:
  // Runs the quick scene into dir_/run (4 frames).
  fs::path make_run(const std::string& extra = "") {
    const auto run = dir_ / "run";
    const auto r = swirl("run " + write_scene("s.toml", kScene).string() + " --out " + run.string() + " --threads 2 " + extra);
    EXPECT_EQ(r.status, 0) << r.err;
    return run;
  }

  // swirl with PATH set to `path` only (to hide or fake ffmpeg).
  Result swirl_with_path(const fs::path& path, const std::string& args) {
    const auto out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = "PATH=" + path.string() + " " + std::string(SWIRL_CLI) + " " + args + " >" + out.string() +
                            " 2>" + err.string();
    Result r;
    const int raw = std::system(cmd.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }
};

TEST_F(Render, DrawsTheLastFrameByDefaultAndAnyFrameAsked) {
  const auto run = make_run();
  auto r = swirl("render " + run.string() + " --size 320x200");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(is_png(slurp(run / "render" / "particles_000003.png"), 320, 200));
  EXPECT_FALSE(fs::exists(run / "render" / "particles_000000.png"));
  r = swirl("render " + run.string() + " --frame 1 --view iso --color density --out " + (dir_ / "pics").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(is_png(slurp(dir_ / "pics" / "particles_000001.png"), 1280, 720));
  EXPECT_NE(r.out.find("particles_000001.png"), std::string::npos) << r.out;
}

TEST_F(Render, AllDrawsEveryFrame) {
  const auto run = make_run();
  const auto r = swirl("render " + run.string() + " --all --size 200x120 --view top --projection perspective");
  ASSERT_EQ(r.status, 0) << r.err;
  for (int k = 0; k < 4; ++k)
    EXPECT_TRUE(is_png(slurp(run / "render" / ("particles_00000" + std::to_string(k) + ".png")), 200, 120)) << k;
}

TEST_F(Render, PicturesAreIdenticalForAnyThreadCount) {
  const auto run = make_run();
  std::string first;
  for (int threads : {1, 2, 3}) {
    const auto out = dir_ / ("t" + std::to_string(threads));
    const auto r = swirl("render " + run.string() + " --frame 2 --size 400x300 --view iso --threads " +
                         std::to_string(threads) + " --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string png = slurp(out / "particles_000002.png");
    ASSERT_FALSE(png.empty());
    if (first.empty()) first = png;
    EXPECT_EQ(png, first) << "threads " << threads;
  }
}

TEST_F(Render, AnEmptyRunDirectoryIsAClearErrorAndWritesNothing) {
  const auto empty = dir_ / "empty";
  fs::create_directories(empty);
  const auto r = swirl("render " + empty.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(empty.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no frames"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(empty));
}

TEST_F(Render, AMissingFrameIsAClearErrorAndWritesNothing) {
  const auto run = make_run();
  const auto r = swirl("render " + run.string() + " --frame 99");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no frame 99"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("0 to 3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(run / "render"));
}

TEST_F(Render, ACorruptFrameIsNamedAndLeavesNoPartialPicture) {
  const auto run = make_run();
  const auto frame = run / "particles_000002.vtp";
  const std::string bytes = slurp(frame);
  std::ofstream(frame, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() * 2 / 3);
  const auto r = swirl("render " + run.string() + " --all");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(frame.string()), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(run / "render" / "particles_000001.png")) << "frames before it are drawn";
  EXPECT_FALSE(fs::exists(run / "render" / "particles_000002.png"));
  for (const auto& e : fs::directory_iterator(run / "render"))
    EXPECT_EQ(e.path().extension(), ".png") << "no temporary file left: " << e.path();
}

TEST_F(Render, BadOptionsAreRefused) {
  const auto run = make_run();
  for (const std::string bad : {"--size 12x", "--size 10x10", "--range 3", "--range 2,1", "--view side",
                                "--color temperature", "--frame 1 --all"}) {
    const auto r = swirl("render " + run.string() + " " + bad);
    EXPECT_NE(r.status, 0) << bad;
    EXPECT_FALSE(r.err.empty()) << bad;
  }
  EXPECT_FALSE(fs::exists(run / "render"));
}

TEST_F(Render, MovieWithoutFfmpegSaysHowToGetItBeforeDrawing) {
  const auto run = make_run();
  const auto no_tools = dir_ / "no_tools";
  fs::create_directories(no_tools);
  const auto r = swirl_with_path(no_tools, "render " + run.string() + " --movie");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("apt-get install ffmpeg"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(run / "render"));
}

TEST_F(Render, MovieHandsTheFramesToFfmpegInOrder) {
  const auto run = make_run();
  // A stand-in ffmpeg: records its arguments and writes its last one (the output).
  const auto tools = dir_ / "tools";
  fs::create_directories(tools);
  const auto fake = tools / "ffmpeg";
  std::ofstream(fake) << "#!/bin/sh\necho \"$@\" > " << (dir_ / "ffmpeg_args.txt").string()
                      << "\nfor a in \"$@\"; do last=\"$a\"; done\n"
                      << "n=0; while [ -e \"${last%/*}/frame_00000$n.png\" ]; do n=$((n+1)); done\n"
                      << "echo \"frames $n\" > \"$last\"\n";
  fs::permissions(fake, fs::perms::owner_all);
  auto r = swirl_with_path(tools, "render " + run.string() + " --movie --fps 12 --size 160x100");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(run / "render" / "movie.mp4"), "frames 4\n");
  EXPECT_NE(slurp(dir_ / "ffmpeg_args.txt").find("-framerate 12"), std::string::npos);
  for (const auto& e : fs::directory_iterator(run / "render"))
    EXPECT_TRUE(e.path().extension() == ".png" || e.path().filename() == "movie.mp4") << "left behind: " << e.path();

  // An ffmpeg that fails: its message is shown and no movie is left.
  fs::remove(run / "render" / "movie.mp4");
  std::ofstream(fake, std::ios::trunc) << "#!/bin/sh\necho 'Unknown encoder libx264' >&2\nexit 1\n";
  r = swirl_with_path(tools, "render " + run.string() + " --movie --size 160x100");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("Unknown encoder libx264"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(run / "render" / "movie.mp4"));
}

// With the real ffmpeg, when it is installed (it is optional).
TEST_F(Render, MovieWithTheRealFfmpegIsAnMp4) {
  if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0) GTEST_SKIP() << "ffmpeg is not installed";
  const auto run = make_run();
  const auto r = swirl("render " + run.string() + " --movie --size 161x101");  // odd sizes are padded
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string movie = slurp(run / "render" / "movie.mp4");
  ASSERT_GT(movie.size(), 12u);
  EXPECT_EQ(movie.substr(4, 4), "ftyp") << "an ISO media file";
}

TEST_F(Render, RunRenderEveryDrawsWhileRunningAndChangesNoFrame) {
  const auto plain = make_run();
  fs::rename(plain, dir_ / "plain");
  const auto run = make_run("--render-every 2");
  EXPECT_TRUE(fs::exists(run / "render" / "particles_000000.png"));
  EXPECT_FALSE(fs::exists(run / "render" / "particles_000001.png"));
  EXPECT_TRUE(fs::exists(run / "render" / "particles_000002.png"));
  EXPECT_FALSE(fs::exists(run / "render" / "particles_000003.png"));
  for (int k = 0; k < 4; ++k) {
    const std::string name = "particles_00000" + std::to_string(k) + ".vtp";
    EXPECT_EQ(slurp(run / name), slurp(dir_ / "plain" / name)) << name;
  }
  // The same pictures as swirl render draws afterwards.
  const auto r = swirl("render " + run.string() + " --frame 2 --out " + (dir_ / "after").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir_ / "after" / "particles_000002.png"), slurp(run / "render" / "particles_000002.png"));
}

TEST_F(Render, RunRenderEveryNeedsVtpFrames) {
  const auto r = swirl("run " + write_scene("s.toml", kScene).string() + " --out " + (dir_ / "csv").string() +
                       " --set 'output.format=\"csv\"' --render-every 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("vtp"), std::string::npos) << r.err;
}

// Every example scene, one step, drawn small. (A scene that stops at the first
// step still leaves frame 0 to draw.)
TEST_F(Render, DrawsEveryExampleScene) {
  for (const auto& e : fs::directory_iterator(fs::path(SWIRL_SOURCE_DIR) / "examples")) {
    if (e.path().extension() != ".toml") continue;
    const auto out = dir_ / e.path().stem();
    const auto run = swirl("run " + e.path().string() + " --steps 1 --threads 2 --out " + out.string());
    EXPECT_TRUE(fs::exists(out / "particles_000000.vtp")) << e.path() << run.err;
    const auto r = swirl("render " + out.string() + " --frame 0 --size 256x144 --threads 2");
    EXPECT_EQ(r.status, 0) << e.path() << r.err;
    EXPECT_TRUE(is_png(slurp(out / "render" / "particles_000000.png"), 256, 144)) << e.path();
  }
}

}  // namespace
