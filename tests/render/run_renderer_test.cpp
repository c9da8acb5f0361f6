#include "swirl/render/run_renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "render/render_test_util.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/render/colormap.hpp"
#include "swirl/render/png.hpp"

namespace swirl::render {
namespace {

namespace fs = std::filesystem;

// A run directory written as swirl run writes one: frames and particles.pvd.
struct FakeRun {
  test::TempDir dir;
  io::PvdSeries series{dir.path / "particles.pvd"};
  int frames = 0;

  // A frame of n particles spread over the unit cube, moved by `shift`, all
  // with speed `speed` and mass 1/n (density 0: no SPH).
  fs::path add_frame(std::size_t n, double time, double shift = 0, double speed = 0, bool write_pvd = true) {
    ParticleSet<double> p(n);
    const auto cloud = test::random_cloud(n, 5);
    for (std::size_t i = 0; i < n; ++i) {
      p.position.set(i, cloud[i] + Vec3d{shift, 0, 0});
      p.velocity.set(i, {speed * (0.5 + 0.5 * static_cast<double>(i) / static_cast<double>(n)), 0, 0});
      p.mass[i] = 1.0 / static_cast<double>(n);
    }
    const std::string name = "particles_" + std::string(6 - std::to_string(frames).size(), '0') + std::to_string(frames) + ".vtp";
    io::write_vtp(dir.path / name, p, time);
    if (write_pvd) series.add(time, name);
    ++frames;
    return dir.path / name;
  }
};

std::string error_of(auto&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

RenderOptions small() {
  RenderOptions o;
  o.width = 240;
  o.height = 160;
  return o;
}

TEST(RunRenderer, AnEmptyDirectoryIsRefusedWithItsName) {
  test::TempDir dir;
  const std::string e = error_of([&] { read_run(dir.path); });
  EXPECT_NE(e.find(dir.path.string()), std::string::npos) << e;
  EXPECT_NE(e.find("no frames"), std::string::npos) << e;
  const std::string missing = error_of([&] { read_run(dir.path / "nope"); });
  EXPECT_NE(missing.find("nope"), std::string::npos) << missing;
}

TEST(RunRenderer, ListsTheFramesOfThePvdOrElseTheVtpFiles) {
  FakeRun run;
  run.add_frame(10, 0.0);
  run.add_frame(10, 0.5);
  EXPECT_EQ(read_run(run.dir.path).frames.size(), 2u);
  fs::remove(run.dir.path / "particles.pvd");
  run.add_frame(10, 1.0, 0, 0, false);
  const auto info = read_run(run.dir.path);
  ASSERT_EQ(info.frames.size(), 3u);
  EXPECT_EQ(info.frames[2].file, "particles_000002.vtp");
  EXPECT_FALSE(info.has_scene);
}

TEST(RunRenderer, ACorruptFrameIsNamedAndLeavesNoPicture) {
  FakeRun run;
  run.add_frame(50, 0.0);
  const fs::path bad = run.add_frame(50, 0.5);
  const std::string bytes = io::read_text_file(bad);
  io::write_file_atomic(bad, bytes.substr(0, bytes.size() / 2));  // truncated
  const RunRenderer renderer(read_run(run.dir.path), small());
  const fs::path png = run.dir.path / "bad.png";
  const std::string e = error_of([&] { renderer.render_file(bad, png); });
  EXPECT_NE(e.find(bad.string()), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(png));
  // Garbage instead of a frame, too.
  io::write_file_atomic(bad, "<VTKFile garbage");
  EXPECT_NE(error_of([&] { renderer.render_file(bad, png); }).find(bad.string()), std::string::npos);
  EXPECT_FALSE(fs::exists(png));
}

TEST(RunRenderer, CameraAndColoursComeFromTheFirstFrameOnly) {
  FakeRun run;
  run.add_frame(200, 0.0, 0.0, 1.0);
  const RunRenderer before(read_run(run.dir.path), small());
  run.add_frame(200, 1.0, 5.0, 50.0);  // moved away and much faster
  const RunRenderer after(read_run(run.dir.path), small());
  EXPECT_EQ(before.range(), after.range());
  EXPECT_EQ(before.camera().target, after.camera().target);
  EXPECT_EQ(before.camera().scale, after.camera().scale);
  // Speeds of the first frame run from 0.5 to 1: the range covers about that.
  EXPECT_NEAR(before.range().first, 0.5, 0.01);
  EXPECT_NEAR(before.range().second, 1.0, 0.01);
}

TEST(RunRenderer, AtRestTheSpeedScaleComesFromTheScene) {
  FakeRun run;
  run.add_frame(20, 0.0);
  std::ofstream(run.dir.path / "scene.toml") << R"([simulation]
dt = 0.001
steps = 10

[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 2.0]

[forces]
gravity = [0.0, 0.0, -8.0]

[[particles]]
kind = "list"
positions = [[0.5, 0.5, 0.5]]
masses = [1.0]
)";
  const RunRenderer renderer(read_run(run.dir.path), small());
  EXPECT_EQ(renderer.range().first, 0);
  EXPECT_DOUBLE_EQ(renderer.range().second, std::sqrt(2 * 8.0 * 2.0));  // free fall across the box height
  EXPECT_TRUE(renderer.run().box.has_value());
}

TEST(RunRenderer, PicturesAreBitIdenticalForAnyThreadCount) {
  FakeRun run;
  run.add_frame(3000, 0.0, 0.0, 1.0);
  const int saved = parallel::thread_count();
  for (View view : {View::Front, View::Iso}) {
    RenderOptions o = small();
    o.view = view;
    const RunRenderer renderer(read_run(run.dir.path), o);
    const Frame frame = load_frame(run.dir.path / "particles_000000.vtp");
    std::string first;
    for (int threads : {1, 2, 3}) {
      parallel::set_thread_count(threads);
      const std::string png = encode_png(renderer.render(frame));
      if (first.empty()) first = png;
      EXPECT_EQ(png, first) << "threads " << threads;
    }
  }
  parallel::set_thread_count(saved);
}

TEST(RunRenderer, DrawsTheParticlesTheTimeAndTheColourBar) {
  FakeRun run;
  run.add_frame(500, 0.0, 0.0, 1.0);
  const RunRenderer renderer(read_run(run.dir.path), small());
  const Image image = renderer.render(load_frame(run.dir.path / "particles_000000.vtp"));
  ASSERT_EQ(image.width(), 240);
  ASSERT_EQ(image.height(), 160);
  const Color background = image.at(0, image.height() - 1);
  auto changed_in = [&](int x0, int x1, int y0, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += image.at(x, y) != background;
    return n;
  };
  const auto centre = renderer.camera().project({0.5, 0.5, 0.5});
  ASSERT_TRUE(centre);
  EXPECT_GT(changed_in(static_cast<int>(centre->x) - 5, static_cast<int>(centre->x) + 5,
                       static_cast<int>(centre->y) - 5, static_cast<int>(centre->y) + 5), 50) << "particles";
  EXPECT_GT(changed_in(0, 80, 0, 20), 10) << "the time, top left";
  // The colour bar's top and bottom are the map's ends.
  bool top = false, bottom = false;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 180; x < image.width(); ++x) {
      top = top || image.at(x, y) == colormap(ColorMap::Viridis, 1.0);
      bottom = bottom || image.at(x, y) == colormap(ColorMap::Viridis, 0.0);
    }
  EXPECT_TRUE(top && bottom);
}

// Boundary particles: the box walls' layer (outside the faces) is not drawn,
// so the fluid behind the near wall shows (the picture, below the caption,
// is the one of the frame without the walls); an obstacle's particles inside
// the box are drawn as a solid, grey, whatever the colour field; the colour
// range and the splats' size come from the fluid alone.
TEST(RunRenderer, WallsAreLeftOutAndObstaclesDrawnAsSolids) {
  RunInfo run;
  run.box = Box<double>{{0, 0, 0}, {1, 1, 1}};
  run.rest_density = 1000;
  Frame fluid_and_obstacle;
  const auto add = [](Frame& f, Vec3d x, double speed, std::int32_t kind, double mass) {
    f.positions.push_back(x);
    f.velocity.push_back({speed, 0, 0});
    f.mass.push_back(mass);
    f.density.push_back(1000);
    f.pressure.push_back(kind ? 5e4 : 100 * x.z);
    f.kind.push_back(kind);
  };
  for (double x = 0.1; x < 0.45; x += 0.04)
    for (double y = 0.3; y < 0.7; y += 0.04)
      for (double z = 0.02; z < 0.4; z += 0.04) add(fluid_and_obstacle, {x, y, z}, 0.5 + x, 0, 0.064);
  for (double x = 0.6; x < 0.9; x += 0.04)
    for (double y = 0.4; y < 0.6; y += 0.04)
      for (double z = 0.02; z < 0.3; z += 0.04) add(fluid_and_obstacle, {x, y, z}, 0, 1, 0.01);
  Frame walled = fluid_and_obstacle;
  for (double x = 0; x <= 1; x += 0.04)  // the two y faces' layers, just outside
    for (double z = 0; z <= 1; z += 0.04)
      for (const double y : {-0.02, 1.02}) add(walled, {x, y, z}, 0, 1, 0.01);

  RenderOptions o = small();
  o.view = View::Front;
  const RunRenderer renderer(walled, run, o), without_walls(fluid_and_obstacle, run, o);
  EXPECT_EQ(renderer.range(), without_walls.range()) << "the range is the fluid's";
  const Image a = renderer.render(walled), b = without_walls.render(fluid_and_obstacle);
  std::size_t differ = 0;
  for (int y = a.height() / 5; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) differ += a.at(x, y) != b.at(x, y);
  EXPECT_EQ(differ, 0u) << "the walls' particles were drawn";
  // Around the obstacle's middle every pixel is grey; around the fluid's none.
  const auto greys_around = [&](Vec3d at) {
    const auto c = renderer.camera().project(at);
    int n = 0;
    for (int y = int(c->y) - 2; y <= int(c->y) + 2; ++y)
      for (int x = int(c->x) - 2; x <= int(c->x) + 2; ++x) {
        const Color p = a.at(x, y);
        n += std::abs(p.r - p.g) < 0.02f && p.b >= p.g && p.b - p.g < 0.1f && p.r > 0.3f;
      }
    return n;
  };
  EXPECT_GE(greys_around({0.74, 0.5, 0.14}), 20) << "the obstacle is drawn as a grey solid (gaps between discs aside)";
  EXPECT_EQ(greys_around({0.26, 0.5, 0.2}), 0) << "the fluid is coloured by its speed";
}

TEST(RunRenderer, RenderEveryDrawsOnlyEveryKthFrame) {
  FakeRun run;
  const auto hook = render_every(run.dir.path, 2, small());
  std::vector<fs::path> claimed;
  const auto claim = [&](const fs::path& p) {
    claimed.push_back(p);
    return p;
  };
  for (int k = 0; k < 5; ++k) hook(run.add_frame(30, 0.1 * k, 0, 1.0), 0.1 * k, claim);
  EXPECT_EQ(claimed.size(), 3u);  // every picture it draws is claimed first
  for (int k = 0; k < 5; ++k) {
    const fs::path png = run.dir.path / "render" / ("particles_00000" + std::to_string(k) + ".png");
    EXPECT_EQ(fs::exists(png), k % 2 == 0) << png;
    if (k % 2 == 0) {
      EXPECT_EQ(read_png(png).width, 240);
    }
  }
}

TEST(RunRenderer, RefusesImpossibleOptions) {
  FakeRun run;
  run.add_frame(10, 0.0);
  RenderOptions tiny = small();
  tiny.width = 10;
  EXPECT_THROW(RunRenderer(read_run(run.dir.path), tiny), std::invalid_argument);
  RenderOptions backwards = small();
  backwards.range = std::pair{2.0, 1.0};
  EXPECT_THROW(RunRenderer(read_run(run.dir.path), backwards), std::invalid_argument);
  RenderOptions pressure = small();
  pressure.color = Quantity::Pressure;  // frames of particles without SPH have pressure 0, not missing
  EXPECT_NO_THROW(RunRenderer(read_run(run.dir.path), pressure));
}

}  // namespace
}  // namespace swirl::render
