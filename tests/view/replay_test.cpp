// `swirl view RUN_DIR` (view/replay.hpp): a run folder's frames listed and
// served to a WebSocket viewer in order, the slider's seek answered with that
// frame's positions, from .vtp frames and from HDF5 snapshots; a folder that
// is not a run's and a frame that does not read are errors naming the file;
// a fluid's run shows its surface, made from the frame shown, without the
// boundary particles.
//
// The run folder is written here with swirl's writers (io::write_vtp, the
// .pvd series, io::write_snapshot): six frames of 40 particles whose
// positions say which frame they are (y = 0.5 + 0.02·k), so a frame received
// can be matched to the one asked for.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <string>
#include <vector>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/render/fluid_surface.hpp"
#include "swirl/view/replay.hpp"
#include "view/ws_client.hpp"

namespace swirl::view {
namespace {

namespace fs = std::filesystem;
using test::Viewer;

constexpr int kFrames = 6;
constexpr std::size_t kParticles = 40;

// Particle i of frame k.
Vec3d position(std::size_t i, int k) { return {0.01 * double(i), 0.5 + 0.02 * k, 0.1 * double(i % 3)}; }

ParticleSet<double> frame_particles(int k) {
  ParticleSet<double> p(kParticles);
  for (std::size_t i = 0; i < kParticles; ++i) {
    p.position.set(i, position(i, k));
    p.velocity.set(i, Vec3d{double(k), 0, 0});
    p.mass[i] = 1;
    p.density[i] = 1000 + k;
    p.id[i] = i;
  }
  return p;
}

class Replay : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("swirl_replay_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    io::PvdSeries series(dir_ / "particles.pvd");
    for (int k = 0; k < kFrames; ++k) {
      const auto name = "particles_00000" + std::to_string(k);
      const double t = 0.25 * k;
      io::write_vtp(dir_ / (name + ".vtp"), frame_particles(k), t);
      series.add(t, name + ".vtp");
      io::SnapshotInfo info;
      info.time = t;
      io::write_snapshot(dir_ / (name + ".h5"), frame_particles(k), info);
    }
  }
  void TearDown() override {
    if (run_.valid()) finish();
    fs::remove_all(dir_);
  }

  void start(const RunFrames& frames, bool paused) {
    frames_ = frames;
    options_.server.port = 0;
    options_.fps = 60;
    options_.start_paused = paused;
    options_.stop = &stop_;
    options_.log = [this](const std::string& line) {
      std::lock_guard lock(log_mutex_);
      log_.push_back(line);
    };
    std::promise<std::uint16_t> listening;
    auto port = listening.get_future();
    options_.on_listening = [&listening](const LiveServer& s) { listening.set_value(s.port()); };
    run_ = std::async(std::launch::async, [this] { return replay_run(frames_, options_); });
    port_ = port.get();
  }
  ViewResult finish() {
    stop_ = true;
    return run_.get();
  }

  // Every particle of `f` where frame k has it, within half a quantisation step.
  static void expect_frame(const DecodedFrame& f, int k) {
    ASSERT_EQ(f.x.size(), kParticles);
    EXPECT_EQ(f.step, std::uint64_t(k)) << "a replayed frame's step field is its index";
    EXPECT_DOUBLE_EQ(f.time, 0.25 * k);
    for (std::size_t i = 0; i < kParticles; ++i) {
      const Vec3d p = position(i, k);
      const float tol[3] = {(f.hi[0] - f.lo[0]) / 65535 + 1e-6f, (f.hi[1] - f.lo[1]) / 65535 + 1e-6f,
                            (f.hi[2] - f.lo[2]) / 65535 + 1e-6f};
      EXPECT_NEAR(f.x[i], p.x, tol[0]) << "frame " << k << " particle " << i;
      EXPECT_NEAR(f.y[i], p.y, tol[1]) << "frame " << k << " particle " << i;
      EXPECT_NEAR(f.z[i], p.z, tol[2]) << "frame " << k << " particle " << i;
    }
  }

  fs::path dir_;
  RunFrames frames_;
  ViewOptions options_;
  std::atomic<bool> stop_{false};
  std::future<ViewResult> run_;
  std::uint16_t port_ = 0;
  std::mutex log_mutex_;
  std::vector<std::string> log_;
};

TEST_F(Replay, OpenRunListsTheFramesOfEitherFormatWithTheirTimes) {
  for (const ReplayFormat format : {ReplayFormat::Auto, ReplayFormat::Vtp, ReplayFormat::Hdf5}) {
    const RunFrames run = open_run(dir_, format);
    ASSERT_EQ(run.frames.size(), std::size_t(kFrames));
    for (int k = 0; k < kFrames; ++k) {
      EXPECT_DOUBLE_EQ(run.frames[std::size_t(k)].time, 0.25 * k);
      EXPECT_EQ(run.frames[std::size_t(k)].file.extension(), format == ReplayFormat::Hdf5 ? ".h5" : ".vtp");
    }
    EXPECT_FALSE(run.scene);  // no scene.toml here: open space, each frame's bounds
  }
  // Both readers give the same frame: positions, and the fields by swirl's names.
  const ReplayFrame a = read_replay_frame(dir_ / "particles_000003.vtp");
  const ReplayFrame b = read_replay_frame(dir_ / "particles_000003.h5");
  EXPECT_EQ(a.y, b.y);
  auto names = [](const ReplayFrame& f) {
    std::vector<std::string> n;
    for (const auto& [name, values] : f.fields) n.push_back(name);
    return n;
  };
  EXPECT_EQ(names(a), names(b));
  ASSERT_FALSE(a.fields.empty());
  EXPECT_EQ(a.fields.front().first, "speed");
  EXPECT_FLOAT_EQ(a.fields.front().second[0], 3.0f);  // |v| of frame 3
  const auto density = std::find_if(a.fields.begin(), a.fields.end(), [](const auto& f) { return f.first == "density"; });
  ASSERT_NE(density, a.fields.end());
  EXPECT_FLOAT_EQ(density->second[0], 1003.0f);
}

TEST_F(Replay, AFolderThatIsNotARunsIsRefusedNamingIt) {
  const fs::path empty = dir_ / "empty";
  fs::create_directories(empty);
  try {
    open_run(empty);
    FAIL() << "an empty folder is not a run folder";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find(empty.string() + ": not a run folder"), std::string::npos) << e.what();
  }
  EXPECT_THROW(open_run(dir_ / "missing"), io::IoError);
  EXPECT_THROW(open_run(dir_ / "particles.pvd"), io::IoError);  // a file, not a folder
  // A .pvd that is not one: the error names it.
  { std::ofstream(empty / "particles.pvd") << "<VTKFile><nonsense"; }
  try {
    open_run(empty);
    FAIL() << "a broken particles.pvd";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("particles.pvd"), std::string::npos) << e.what();
  }
}

// Playing: the frames arrive in order, from the first to the last (a viewer
// may skip one it was too slow for, never go back); then seek and step.
TEST_F(Replay, FramesArriveInOrderAndASeekShowsThatFrame) {
  for (const ReplayFormat format : {ReplayFormat::Vtp, ReplayFormat::Hdf5}) {
    SCOPED_TRACE(format == ReplayFormat::Vtp ? "vtp" : "h5");
    stop_ = false;
    start(open_run(dir_, format), /*paused=*/false);
    Viewer v(port_);
    auto [text, hello] = v.next();
    ASSERT_TRUE(text);
    EXPECT_NE(hello.find(R"("mode":"replay")"), std::string::npos) << hello;
    EXPECT_NE(hello.find(R"("frames":6,"times":[0,0.25,0.5,0.75,1,1.25])"), std::string::npos) << hello;
    EXPECT_NE(hello.find(R"("fields":["speed",)"), std::string::npos) << hello;
    std::vector<std::uint64_t> order;
    for (int k = 0; k < 50 && (order.empty() || order.back() < kFrames - 1); ++k) {
      const DecodedFrame f = v.frame();
      order.push_back(f.step);
      expect_frame(f, int(f.step));
    }
    ASSERT_FALSE(order.empty());
    EXPECT_EQ(order.back(), std::uint64_t(kFrames - 1)) << "playing reaches the last frame";
    EXPECT_TRUE(std::is_sorted(order.begin(), order.end()) &&
                std::adjacent_find(order.begin(), order.end()) == order.end())
        << "frames in order, each once";
    EXPECT_GE(order.size(), 3u);

    v.send(encode_control(control::Seek{2}));
    expect_frame(v.frame(), 2);
    v.send(encode_control(control::Step{}));  // at the end it paused: a step is the next frame
    expect_frame(v.frame(), 3);
    v.send(encode_control(control::Seek{kFrames}));  // past the end: refused, nothing shown
    EXPECT_NE(test::next_text(v, "refused").find("seek to frame 6: the run has 6 frames"), std::string::npos);
    v.send(encode_control(control::Parameter{control::ParameterId::Viscosity, {1, 0, 0}}));
    EXPECT_NE(test::next_text(v, "refused").find("not a replay"), std::string::npos);
    v.send(encode_control(control::Seek{1}));
    expect_frame(v.frame(), 1);
    const ViewResult r = finish();
    EXPECT_EQ(r.refused, 2u);
    EXPECT_GE(r.frames_read, std::uint64_t(kFrames));
  }
}

// A frame that does not read: the error names its file, on the page and in
// the log; the replay stays on the frame it showed and goes on.
TEST_F(Replay, AFrameThatDoesNotReadIsAnErrorNamingItsFile) {
  const RunFrames frames = open_run(dir_);
  { std::ofstream(dir_ / "particles_000004.vtp", std::ios::trunc) << "<VTKFile type=\"PolyData\">"; }
  start(frames, /*paused=*/true);
  Viewer v(port_);
  expect_frame(v.frame(), 0);
  v.send(encode_control(control::Seek{4}));
  const std::string error = test::next_text(v, "error");
  EXPECT_NE(error.find("particles_000004.vtp"), std::string::npos) << error;
  v.send(encode_control(control::Seek{5}));
  expect_frame(v.frame(), 5);
  finish();
  bool logged = false;
  for (const auto& line : log_) logged |= line.find("particles_000004.vtp") != std::string::npos;
  EXPECT_TRUE(logged);
  // The first frame unreadable: the session does not start, and says which file.
  { std::ofstream(dir_ / "particles_000000.vtp", std::ios::trunc) << "garbage"; }
  ViewOptions options;
  options.server.port = 0;
  const std::atomic<bool> stopped{true};  // were it to start, it would end at once
  options.stop = &stopped;
  try {
    replay_run(frames, options);
    FAIL() << "an unreadable first frame";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("particles_000000.vtp"), std::string::npos) << e.what();
  }
}

// A run of two frames of a block of water (6 × 6 × 6 particles 1 cm apart,
// moved 5 cm along x in the second) over a floor of boundary particles
// (kind 1), without a scene.toml: the volumes are m/ρ of each particle. With
// --surface a viewer gets the surface of the frame shown, the block's alone
// (the mesh render::frame_surface makes of the file), and the next frame's
// after a seek.
TEST(ReplaySurface, AFluidRunShowsTheSurfaceOfTheFrameShown) {
  const fs::path dir = fs::temp_directory_path() /
                       ("swirl_replay_surface_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  constexpr double s = 0.01;
  io::PvdSeries series(dir / "particles.pvd");
  for (int k = 0; k < 2; ++k) {
    ParticleSet<double> p(216 + 100);
    const std::size_t kind = p.add_int_field("kind");
    std::size_t i = 0;
    for (int c = 0; c < 216; ++c, ++i) {
      p.position.set(i, Vec3d{0.1 + 0.05 * k + s * (c % 6), 0.1 + s * (c / 6 % 6), 0.02 + s * (c / 36)});
      p.mass[i] = 1000 * s * s * s;
      p.density[i] = 1000;
    }
    for (int c = 0; c < 100; ++c, ++i) {  // the floor: 10 × 10 boundary particles
      p.position.set(i, Vec3d{0.08 + s * (c % 10), 0.08 + s * (c / 10), 0.0});
      p.mass[i] = 0.4 * 1000 * s * s * s;  // a volume weight, not water
      p.density[i] = 1000;
      p.int_field(kind)[i] = 1;
    }
    for (i = 0; i < p.size(); ++i) p.id[i] = i;
    const std::string name = "particles_00000" + std::to_string(k) + ".vtp";
    io::write_vtp(dir / name, p, 0.1 * k);
    series.add(0.1 * k, name);
  }
  ViewOptions options;
  options.server.port = 0;
  options.fps = 60;
  options.start_paused = true;
  options.surface = true;
  std::atomic<bool> stop{false};
  options.stop = &stop;
  std::promise<std::uint16_t> listening;
  auto port = listening.get_future();
  options.on_listening = [&listening](const LiveServer& server) { listening.set_value(server.port()); };
  const RunFrames frames = open_run(dir);
  auto run = std::async(std::launch::async, [&] { return replay_run(frames, options); });
  {
    Viewer v(port.get());
    auto [text, hello] = v.next();
    EXPECT_NE(hello.find(R"("surface":true,"surface_on":true)"), std::string::npos) << hello;
    render::FluidSurface settings;  // the view's: m/ρ, cell 1 spacing
    settings.cell = 1.0;
    for (int k = 0; k < 2; ++k) {
      if (k == 1) v.send(encode_control(control::Seek{1}));
      DecodedMesh m = v.mesh();
      for (int tries = 0; tries < 10 && m.step != std::uint64_t(k); ++tries) m = v.mesh();
      ASSERT_EQ(m.step, std::uint64_t(k));
      const render::SurfaceMesh expected =
          render::frame_surface(render::load_frame(dir / ("particles_00000" + std::to_string(k) + ".vtp")), settings);
      EXPECT_EQ(m.indices, expected.indices) << "frame " << k;
      EXPECT_EQ(m.vertices.size(), expected.vertices.size()) << "frame " << k;
      EXPECT_NEAR(m.lo[0], 0.1 + 0.05 * k - s, 0.5 * s) << "the block's surface, not the floor's (from 0.08)";
      EXPECT_GT(m.lo[2], 0.005) << "the floor is not water";
      render::SurfaceMesh back;
      back.vertices = m.vertices;
      back.indices = m.indices;
      EXPECT_NEAR(render::enclosed_volume(back) / render::enclosed_volume(expected), 1.0, 1e-4);
      EXPECT_NEAR(render::enclosed_volume(back) / (216 * s * s * s), 0.93, 0.04) << "a small cube's rounded edges";
    }
  }
  stop = true;
  const ViewResult r = run.get();
  EXPECT_GE(r.mesher.meshes, 2u);
  fs::remove_all(dir);
}

// Not a fluid's run (the fixture's frames lack nothing, but a gravity run's
// scene says so): --surface is refused at once, naming the folder.
TEST_F(Replay, SurfaceNeedsAFluidsRun) {
  io::write_file_atomic(dir_ / "scene.toml", R"([simulation]
dt = 0.01
steps = 2

[nbody]
softening = 0.05

[[particles]]
kind = "plummer"
count = 64
seed = 1
)");
  const RunFrames frames = open_run(dir_);
  ASSERT_TRUE(frames.scene) << frames.scene_note;
  ViewOptions options;
  options.server.port = 0;
  options.surface = true;
  const std::atomic<bool> stopped{true};
  options.stop = &stopped;
  try {
    replay_run(frames, options);
    FAIL() << "--surface on a gravity run";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--surface"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a fluid's run"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace swirl::view
