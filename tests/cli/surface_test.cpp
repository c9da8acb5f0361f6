// The fluid surface as a user meets it: output.surface = "ply" in `swirl run`,
// `swirl render --surface`, and the refusals.
#include <gtest/gtest.h>

#include <string>

#include "cli/cli_support.hpp"
#include "swirl/render/obj.hpp"
#include "swirl/render/png.hpp"
#include "swirl/render/ply.hpp"

namespace {

// A small block of water dropping in a box: about 500 particles, 3 frames.
std::string fluid_scene(const std::string& output) {
  return R"([simulation]
dt = 2e-4
steps = 20

[box]
min = [0.0, 0.0, 0.0]
max = [0.3, 0.3, 0.3]

[sph]
neighbours = 30
rest_density = 1000.0
sound_speed = 20.0
viscosity = 0.5

[output]
interval = 0.002
)" + output + R"(

[[particles]]
kind = "fluid_block"
min = [0.1, 0.1, 0.05]
max = [0.2, 0.2, 0.15]
spacing = 0.0125
)";
}

class Surface : public Cli {};

TEST_F(Surface, RunWritesAClosedMeshPerFrameAndASeries) {
  const auto run = dir_ / "run";
  const auto r = swirl("run " + write_scene("s.toml", fluid_scene("surface = \"ply\"")).string() + " --out " +
                       run.string() + " --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* name : {"surface_000000.ply", "surface_000001.ply", "surface_000002.ply"}) {
    ASSERT_TRUE(fs::exists(run / name)) << name;
    const auto ply = swirl::render::read_ply(run / name);
    EXPECT_GT(ply.mesh.triangle_count(), 100u) << name;
    // 8 × 8 × 8 particles of (0.0125 m)³: 1e-3 m³, rounded edges and corners lose a little.
    const double v = swirl::render::enclosed_volume(ply.mesh);
    EXPECT_GT(v, 0.9e-3) << name;
    EXPECT_LT(v, 1.05e-3) << name;
  }
  EXPECT_EQ(swirl::render::read_ply(run / "surface_000000.ply").time, 0.0);
  const std::string series = slurp(run / "surface.ply.series");
  EXPECT_NE(series.find("\"file-series-version\" : \"1.0\""), std::string::npos) << series;
  EXPECT_NE(series.find("{ \"name\" : \"surface_000002.ply\", \"time\" : 0.004"), std::string::npos) << series;
  // The run's own files: a rerun with --overwrite deletes and remakes them.
  const auto again = swirl("run " + (dir_ / "s.toml").string() + " --out " + run.string() + " --overwrite");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_TRUE(fs::exists(run / "surface_000002.ply"));
}

TEST_F(Surface, NeverOverwritesAFileTheRunDidNotMake) {
  const auto run = dir_ / "run";
  fs::create_directories(run);
  { std::ofstream(run / "surface_000000.ply") << "mine"; }
  const auto r = swirl("run " + write_scene("s.toml", fluid_scene("surface = \"ply\"")).string() + " --out " + run.string());
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(slurp(run / "surface_000000.ply"), "mine");
}

// output.surface = "obj": the same meshes as "ply", as OBJ text, and no series
// (ParaView's OBJ reader takes one file).
TEST_F(Surface, ObjHoldsTheMeshesThePlyDoes) {
  const auto ply = dir_ / "ply", obj = dir_ / "obj";
  ASSERT_EQ(swirl("run " + write_scene("p.toml", fluid_scene("surface = \"ply\"")).string() + " --out " + ply.string())
                .status, 0);
  const auto r = swirl("run " + write_scene("o.toml", fluid_scene("surface = \"obj\"")).string() + " --out " +
                       obj.string() + " --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* frame : {"000000", "000001", "000002"}) {
    const std::string name = std::string("surface_") + frame;
    ASSERT_TRUE(fs::exists(obj / (name + ".obj"))) << name;
    EXPECT_FALSE(fs::exists(obj / (name + ".ply"))) << name;
    const auto a = swirl::render::read_ply(ply / (name + ".ply"));
    const auto b = swirl::render::read_obj(obj / (name + ".obj"));
    EXPECT_EQ(b.mesh.vertices.size(), a.mesh.vertices.size()) << name;
    EXPECT_EQ(b.mesh.triangle_count(), a.mesh.triangle_count()) << name;
    EXPECT_GT(b.mesh.triangle_count(), 100u) << name;
    EXPECT_EQ(swirl::render::enclosed_volume(b.mesh), swirl::render::enclosed_volume(a.mesh)) << name;
    EXPECT_EQ(b.time, a.time) << name;
  }
  EXPECT_FALSE(fs::exists(obj / "surface.ply.series"));
  EXPECT_FALSE(fs::exists(obj / "surface.obj.series"));
  // Claimed in the run's manifest: --overwrite deletes and remakes them.
  EXPECT_NE(slurp(obj / "manifest.txt").find("surface_000002.obj"), std::string::npos);
  const auto again = swirl("run " + (dir_ / "o.toml").string() + " --out " + obj.string() + " --overwrite");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_TRUE(fs::exists(obj / "surface_000002.obj"));
}

TEST_F(Surface, AnUnknownFormatIsRefusedNamingTheKeyAndTheChoices) {
  const auto r = swirl("run " + write_scene("x.toml", fluid_scene("surface = \"stl\"")).string() + " --out " +
                       (dir_ / "x").string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("output.surface"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stl"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("obj"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x" / "particles_000000.vtp"));
}

TEST_F(Surface, RenderDrawsWater) {
  const auto run = dir_ / "run";
  ASSERT_EQ(swirl("run " + write_scene("s.toml", fluid_scene("")).string() + " --out " + run.string()).status, 0);
  const auto r = swirl("render " + run.string() + " --surface --size 320x200 --view iso --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("water surface"), std::string::npos) << r.out;
  const auto png = swirl::render::read_png(run / "render" / "particles_000002.png");
  ASSERT_EQ(png.width, 320);
  int water = 0;
  for (std::size_t p = 0; p + 2 < png.rgb.size(); p += 3) {
    const int red = png.rgb[p], green = png.rgb[p + 1], blue = png.rgb[p + 2];
    if (blue > red + 40 && blue > 60 && green > red) ++water;  // bluish, not the grey background or text
  }
  EXPECT_GT(water, 500) << "water-coloured pixels";
  // The same picture for 1 thread.
  const auto one = swirl("render " + run.string() + " --surface --size 320x200 --view iso --threads 1 --out " +
                         (dir_ / "one").string());
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_EQ(slurp(dir_ / "one" / "particles_000002.png"), slurp(run / "render" / "particles_000002.png"));
}

TEST_F(Surface, GravitySceneWithSurfaceIsRefusedNamingTheKey) {
  const auto scene = write_scene("g.toml", R"([simulation]
dt = 0.01
steps = 2

[nbody]
softening = 0.05

[output]
surface = "ply"

[[particles]]
kind = "plummer"
count = 64
seed = 1
)");
  const auto r = swirl("run " + scene.string() + " --out " + (dir_ / "g").string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("output.surface"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[sph]"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "g" / "particles_000000.vtp"));
}

TEST_F(Surface, SurfaceNeedsFramesItCanRead) {
  const auto r = swirl("run " + write_scene("c.toml", fluid_scene("surface = \"ply\"\nformat = \"csv\"")).string() +
                       " --out " + (dir_ / "c").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("output.surface"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\"vtp\""), std::string::npos) << r.err;
}

}  // namespace
