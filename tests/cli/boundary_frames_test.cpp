// Boundary particles in their own frames (sim/run.cpp's FrameWriter,
// io/frame_names.hpp): particles_NNNNNN.* hold the fluid, boundary_NNNNNN.*
// the boundary particles (once when they never move, with every frame when an
// obstacle moves), each series with its .pvd and .xdmf; a resume continues
// both series; the renderer and the replay read a particle frame back whole.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/frame_names.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/render/frame.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/run.hpp"
#include "swirl/view/replay.hpp"

namespace fs = std::filesystem;
using namespace swirl;

namespace {

// A 0.12 × 0.06 × 0.1 m tank of particle walls, a water block and a box
// obstacle (moving as a piston when `moving`): about 300 fluid and 1 700
// boundary particles, a frame every step.
std::string tank(bool moving) {
  return fmt::format(R"(
[simulation]
precision = "double"
dt = 0.002
end_time = 1
block_size = 64

[box]
min = [0.0, 0.0, 0.0]
max = [0.12, 0.06, 0.1]
walls = "particles"

[forces]
gravity = [0.0, 0.0, -9.81]

[sph]
neighbours = 30
rest_density = 1000.0
sound_speed = 20.0
viscosity = 0.05
method = "dfsph"

[output]
interval = 0.002
format = ["vtp", "hdf5", "csv"]

[[particles]]
kind = "fluid_block"
min = [0.04, 0.0, 0.0]
max = [0.12, 0.06, 0.04]
spacing = 0.01

[[particles]]
kind = "obstacle_box"
min = [0.01, 0.0, 0.0]
max = [0.02, 0.06, 0.06]
name = "paddle"
{motion}
)",
                     fmt::arg("motion", moving ? R"(motion = { kind = "piston", direction = [1, 0, 0], amplitude = 0.005, frequency = 5 })"
                                               : ""));
}

class Folder {
 public:
  explicit Folder(std::string_view name)
      : path_(fs::temp_directory_path() / fmt::format("swirl_bframes_{}_{}", name, ::getpid())) {
    fs::remove_all(path_);
  }
  ~Folder() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

sim::RunSummary run(const std::string& text, const fs::path& out, std::uint64_t steps, bool resume = false,
                    std::optional<std::uint64_t> checkpoint_every_steps = {}) {
  sim::RunOptions options;
  options.out_dir = out;
  options.threads = 1;
  options.steps = steps;
  options.resume = resume;
  options.checkpoint_every_steps = checkpoint_every_steps;
  return sim::run_scene(scene::parse_scene(text, "scene.toml"), options);
}

// The kind and id arrays of a .vtp frame.
struct KindsAndIds {
  std::vector<std::int32_t> kinds;
  std::vector<std::uint64_t> ids;
};
KindsAndIds kinds_and_ids(const fs::path& file) {
  const io::VtpFile vtp = io::read_vtp(file);
  KindsAndIds out;
  out.kinds = vtp.point_data.at("kind").values<std::int32_t>();
  const auto& id = vtp.point_data.at("id");
  if (id.type == "UInt64") out.ids = id.values<std::uint64_t>();
  else for (auto v : id.values<std::int64_t>()) out.ids.push_back(std::uint64_t(v));
  return out;
}

// The particle rows of a CSV frame (after its time comment and its header).
std::size_t csv_rows(const fs::path& file) {
  const std::string text = io::read_text_file(file);
  return std::size_t(std::count(text.begin(), text.end(), '\n')) - 2;
}

std::vector<std::string> files_of(const fs::path& dir, std::string_view series) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    if (io::frame_index(e.path(), series)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST(FrameNames, NameAndIndexRoundTripAndTheBoundaryFrameInForceIsTheLatestNotAfter) {
  EXPECT_EQ(io::frame_file_name(io::kBoundarySeries, 7, ".vtp"), "boundary_000007.vtp");
  EXPECT_EQ(io::frame_file_name(io::kParticleSeries, 1234567, ".h5"), "particles_1234567.h5");
  EXPECT_EQ(io::frame_index("a/particles_000042.csv", io::kParticleSeries), 42u);
  EXPECT_FALSE(io::frame_index("a/particles_000042.csv", io::kBoundarySeries));
  EXPECT_FALSE(io::frame_index("particles_.vtp", io::kParticleSeries));
  EXPECT_FALSE(io::frame_index("particles_00x1.vtp", io::kParticleSeries));
  EXPECT_FALSE(io::frame_index("particlesX000001.vtp", io::kParticleSeries));
  Folder dir("names");
  fs::create_directories(dir.path());
  for (const char* name : {"boundary_000000.vtp", "boundary_000003.vtp", "boundary_000005.h5", "particles_000004.vtp"})
    io::write_file_atomic(dir.path() / name, "x");
  EXPECT_EQ(io::boundary_frame_for(dir.path() / "particles_000004.vtp"), dir.path() / "boundary_000003.vtp");
  EXPECT_EQ(io::boundary_frame_for(dir.path() / "particles_000002.vtp"), dir.path() / "boundary_000000.vtp");
  EXPECT_EQ(io::boundary_frame_for(dir.path() / "particles_000003.vtp"), dir.path() / "boundary_000003.vtp");
  EXPECT_FALSE(io::boundary_frame_for(dir.path() / "particles_000004.h5"));  // boundary_000005.h5 is later
  EXPECT_FALSE(io::boundary_frame_for(dir.path() / "boundary_000004.vtp"));  // not a particle frame
}

TEST(BoundaryFrames, StaticBoundaryParticlesAreWrittenOnceInTheirOwnSeriesInEveryFormat) {
  Folder out("static");
  const auto summary = run(tank(false), out.path(), 3);
  ASSERT_TRUE(summary.error.empty()) << summary.error;
  const fs::path& d = out.path();
  EXPECT_EQ(files_of(d, io::kParticleSeries).size(), 12u);  // frames 0..3 in three formats
  EXPECT_EQ(files_of(d, io::kBoundarySeries),
            (std::vector<std::string>{"boundary_000000.csv", "boundary_000000.h5", "boundary_000000.vtp"}));
  ASSERT_EQ(io::read_pvd(d / "particles.pvd").size(), 4u);
  const auto walls_listed = io::read_pvd(d / "boundary.pvd");
  ASSERT_EQ(walls_listed.size(), 1u);
  EXPECT_EQ(walls_listed[0].file, "boundary_000000.vtp");
  EXPECT_EQ(walls_listed[0].time, 0.0);

  // Each series holds one kind; together the ids are every particle once.
  const KindsAndIds fluid = kinds_and_ids(d / "particles_000003.vtp");
  const KindsAndIds walls = kinds_and_ids(d / "boundary_000000.vtp");
  ASSERT_GT(fluid.kinds.size(), 100u);
  ASSERT_GT(walls.kinds.size(), 100u);
  EXPECT_TRUE(std::all_of(fluid.kinds.begin(), fluid.kinds.end(), [](auto k) { return !is_boundary(k); }));
  EXPECT_TRUE(std::all_of(walls.kinds.begin(), walls.kinds.end(), [](auto k) { return is_boundary(k); }));
  std::set<std::uint64_t> ids(fluid.ids.begin(), fluid.ids.end());
  ids.insert(walls.ids.begin(), walls.ids.end());
  const std::size_t n = fluid.ids.size() + walls.ids.size();
  ASSERT_EQ(ids.size(), n);
  EXPECT_EQ(*ids.rbegin(), n - 1);

  // HDF5: the fluid as PartType0, the walls as PartType2 in their own file;
  // each series its own XDMF collection naming its group.
  EXPECT_EQ(io::read_snapshot(d / "particles_000003.h5").count, fluid.ids.size());
  const io::SnapshotFile h5_walls = io::read_snapshot(d / "boundary_000000.h5", 2);
  EXPECT_EQ(h5_walls.count, walls.ids.size());
  EXPECT_EQ(h5_walls.info.type, io::PartType::Boundary);
  const std::string xdmf = io::read_text_file(d / "boundary.xdmf");
  EXPECT_NE(xdmf.find("Grid Name=\"boundary\""), std::string::npos);
  EXPECT_NE(xdmf.find("boundary_000000.h5:/PartType2/Coordinates"), std::string::npos);
  EXPECT_NE(io::read_text_file(d / "particles.xdmf").find("particles_000003.h5:/PartType0/Coordinates"),
            std::string::npos);
  // CSV: the same split.
  EXPECT_EQ(csv_rows(d / "boundary_000000.csv"), walls.ids.size());
  EXPECT_EQ(csv_rows(d / "particles_000003.csv"), fluid.ids.size());

  // Read back whole by the renderer and by the replay, from either format.
  for (const char* ext : {".vtp", ".h5"}) {
    const fs::path frame = d / fmt::format("particles_000003{}", ext);
    const render::Frame f = render::load_frame(frame);
    ASSERT_EQ(f.positions.size(), n) << ext;
    ASSERT_EQ(f.kind.size(), n) << ext;
    EXPECT_EQ(std::size_t(std::count_if(f.kind.begin(), f.kind.end(), [](auto k) { return is_boundary(k); })),
              walls.ids.size()) << ext;
    EXPECT_EQ(f.pressure.size(), n) << ext;
    const view::ReplayFrame r = view::read_replay_frame(frame);
    ASSERT_EQ(r.x.size(), n) << ext;
    const auto kind = std::find_if(r.fields.begin(), r.fields.end(), [](const auto& p) { return p.first == "kind"; });
    ASSERT_NE(kind, r.fields.end()) << ext;
    EXPECT_EQ(kind->second.size(), n) << ext;
    EXPECT_EQ(std::count(kind->second.begin(), kind->second.end(), 1.0f), std::ptrdiff_t(walls.ids.size())) << ext;
  }
}

TEST(BoundaryFrames, AMovingObstacleIsWrittenWithEveryFrameAStaticOneOnceAndAResumeContinuesBothSeriesByteForByte) {
  for (const bool moving : {true, false}) {
    SCOPED_TRACE(moving ? "moving" : "static");
    Folder straight("straight"), stopped("stopped");
    ASSERT_TRUE(run(tank(moving), straight.path(), 6).error.empty());
    const std::vector<std::string> walls = files_of(straight.path(), io::kBoundarySeries);
    EXPECT_EQ(walls.size(), (moving ? 7u : 1u) * 3u);  // frames 0..6 (or 0) in three formats
    ASSERT_EQ(io::read_pvd(straight.path() / "boundary.pvd").size(), moving ? 7u : 1u);
    // The paddle moved between the first and the last frame.
    if (moving) {
      EXPECT_NE(io::read_text_file(straight.path() / "boundary_000000.csv").substr(40),
                io::read_text_file(straight.path() / "boundary_000006.csv").substr(40));
    }

    // Stopped after 5 steps with a checkpoint at 3, resumed for the 3 after it.
    ASSERT_TRUE(run(tank(moving), stopped.path(), 5, false, 3).error.empty());
    const auto resumed = run(tank(moving), stopped.path(), 3, true);
    ASSERT_TRUE(resumed.error.empty()) << resumed.error;
    EXPECT_EQ(files_of(stopped.path(), io::kBoundarySeries), walls);
    for (const auto& name : walls)
      EXPECT_EQ(io::read_text_file(stopped.path() / name), io::read_text_file(straight.path() / name)) << name;
    for (const char* listing : {"boundary.pvd", "boundary.xdmf", "particles.pvd", "particles.xdmf"})
      EXPECT_EQ(io::read_text_file(stopped.path() / listing), io::read_text_file(straight.path() / listing)) << listing;
  }
}
