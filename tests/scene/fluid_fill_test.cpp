// [[particles]] kind = "fluid_sphere" and "fluid_mesh" (scene/fluid_fill.hpp):
// the fluid_block's lattice over the shape's bounds, the points inside kept.
// Counts against the analytic volume / spacing³, every point inside by an
// independent test, a mesh cube giving exactly the fluid_block's points, the
// fluid_block's mass, and refusals (open or inconsistently oriented mesh, a
// sphere leaving the box) naming the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/io_test_util.hpp"
#include "scene/mesh_test_util.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/scene/fluid_fill.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::scene {
namespace {

using io::test::TempDir;

// A DFSPH tank [0, 2]³ with the one source `source`.
std::string fill_scene(const std::string& source) {
  return fmt::format(R"([simulation]
precision = "double"
dt = 0.001
steps = 1
[box]
min = [0, 0, 0]
max = [2, 2, 2]
[sph]
method = "dfsph"
smoothing_length = 0.2
[[particles]]
{}
)",
                     source);
}

Scene load_in(const TempDir& dir, const std::string& source) {
  io::test::spit(dir / "scene.toml", fill_scene(source));
  return load_scene(dir / "scene.toml");
}

std::string error_of(const TempDir& dir, const std::string& source) {
  try {
    (void)load_in(dir, source);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(accepted)";
}

std::vector<Vec3d> positions(const Scene& s) {
  const auto p = make_particles<double>(s);
  std::vector<Vec3d> out;
  for (std::size_t i = 0; i < p.size(); ++i) out.push_back(p.position.get(i));
  return out;
}

TEST(FluidFill, ASphereHoldsItsVolumeOverSpacingCubedAndEveryPointIsInside) {
  TempDir dir;
  const Vec3d c{1.0, 0.9, 1.1};
  const double r = 0.5, s = 0.04;
  const Scene scene = load_in(dir, "kind = \"fluid_sphere\"\ncenter = [1.0, 0.9, 1.1]\nradius = 0.5\nspacing = 0.04");
  const auto x = positions(scene);
  const double expected = 4.0 / 3.0 * std::numbers::pi * r * r * r / (s * s * s);  // 8181.2
  EXPECT_EQ(x.size(), count_particles(scene));
  // A lattice count differs from V/s³ by the cells the surface cuts: well within 1.5 % here.
  EXPECT_NEAR(double(x.size()), expected, 0.015 * expected);
  for (const Vec3d& p : x) EXPECT_LT(norm(p - c), r);
  // The same mass as a fluid_block at the spacing.
  const Scene block = load_in(dir, "kind = \"fluid_block\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nspacing = 0.04");
  EXPECT_EQ(std::get<FluidFillSource>(scene.sources[0]).mass, std::get<LatticeSource>(block.sources[0]).mass);
  EXPECT_GT(std::get<FluidFillSource>(scene.sources[0]).mass, 0);
}

TEST(FluidFill, AMeshCubeGivesExactlyTheFluidBlocksPoints) {
  TempDir dir;
  io::test::spit(dir / "cube.stl", test::ascii_stl(test::unit_cube()));
  const auto mesh = positions(load_in(dir, "kind = \"fluid_mesh\"\nfile = \"cube.stl\"\ntranslate = [0.5, 0.25, 0.75]\nspacing = 0.1"));
  const auto block =
      positions(load_in(dir, "kind = \"fluid_block\"\nmin = [0.5, 0.25, 0.75]\nmax = [1.5, 1.25, 1.75]\nspacing = 0.1"));
  EXPECT_EQ(block.size(), 1000u);
  EXPECT_EQ(mesh, block);
  // Normals inward (every triangle reversed) fill the same points.
  test::Mesh inward = test::unit_cube();
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  io::test::spit(dir / "inward.stl", test::ascii_stl(inward));
  EXPECT_EQ(positions(load_in(dir, "kind = \"fluid_mesh\"\nfile = \"inward.stl\"\ntranslate = [0.5, 0.25, 0.75]\nspacing = 0.1")),
            block);
}

// Inside the step block's L profile (x, z in mm), extruded 0 ≤ y ≤ 200 mm.
bool in_step_block(const Vec3d& mm) {
  if (mm.y <= 0 || mm.y >= 200 || mm.x <= 0 || mm.z <= 0) return false;
  return (mm.x < 240 && mm.z < 80) || (mm.x < 120 && mm.z < 160);
}

TEST(FluidFill, ATurnedNonConvexMeshHoldsItsVolumeAndEveryPointIsInside) {
  TempDir dir;
  io::test::spit(dir / "step.stl", test::ascii_stl(test::step_block()));
  const double s = 0.01, turn = 30 * std::numbers::pi / 180;
  const Vec3d shift{0.8, 0.6, 0.4};
  const Scene scene = load_in(dir, "kind = \"fluid_mesh\"\nfile = \"step.stl\"\nscale = 0.001\n"
                                   "rotate_deg = [0, 0, 30]\ntranslate = [0.8, 0.6, 0.4]\nspacing = 0.01");
  const auto x = positions(scene);
  const double volume = (0.24 * 0.08 + 0.12 * 0.08) * 0.2;  // 5.76e-3 m³: 5760 spacings³
  EXPECT_NEAR(double(x.size()), volume / (s * s * s), 0.03 * volume / (s * s * s));
  for (const Vec3d& p : x) {
    const Vec3d q = p - shift;  // turned back by −30° about z, in mm
    const Vec3d mm{(q.x * std::cos(turn) + q.y * std::sin(turn)) * 1000, (-q.x * std::sin(turn) + q.y * std::cos(turn)) * 1000,
                   q.z * 1000};
    EXPECT_TRUE(in_step_block(mm)) << mm.x << " " << mm.y << " " << mm.z;
  }
  // Unturned, the block lines up with the lattice cells: exactly 24 × 20 × 16 minus the notch.
  const Scene straight = load_in(dir, "kind = \"fluid_mesh\"\nfile = \"step.stl\"\nscale = 0.001\nspacing = 0.01");
  EXPECT_EQ(positions(straight).size(), 5760u);
}

TEST(FluidFill, TheWindingNumberIsOneInsideAndZeroOutside) {
  const test::Mesh cube = test::unit_cube();
  io::TriangleMesh m;
  m.vertices = cube.vertices;
  for (const auto& t : cube.triangles)
    m.triangles.push_back({std::uint32_t(t[0]), std::uint32_t(t[1]), std::uint32_t(t[2])});
  EXPECT_NEAR(winding_number(m.vertices, m, {0.3, 0.6, 0.2}), 1.0, 1e-12);
  EXPECT_NEAR(winding_number(m.vertices, m, {1.3, 0.6, 0.2}), 0.0, 1e-12);
  EXPECT_NEAR(winding_number(m.vertices, m, {0.999, 0.001, 0.5}), 1.0, 1e-9);  // near an edge
  EXPECT_EQ(mesh_closure_problem(m), "");
}

TEST(FluidFill, RefusesAnOpenOrMisorientedMeshAndASphereOutsideTheBoxNamingFileAndKey) {
  TempDir dir;
  test::Mesh open = test::unit_cube();
  open.triangles.pop_back();
  io::test::spit(dir / "open.stl", test::ascii_stl(open));
  std::string e = error_of(dir, "kind = \"fluid_mesh\"\nfile = \"open.stl\"\ntranslate = [0.5, 0.5, 0.5]\nspacing = 0.1");
  EXPECT_NE(e.find("scene.toml"), std::string::npos) << e;
  EXPECT_NE(e.find("particles[0].file"), std::string::npos) << e;
  EXPECT_NE(e.find("open.stl"), std::string::npos) << e;
  EXPECT_NE(e.find("not closed"), std::string::npos) << e;
  test::Mesh flipped = test::unit_cube();
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  io::test::spit(dir / "flipped.stl", test::ascii_stl(flipped));
  e = error_of(dir, "kind = \"fluid_mesh\"\nfile = \"flipped.stl\"\ntranslate = [0.5, 0.5, 0.5]\nspacing = 0.1");
  EXPECT_NE(e.find("flipped.stl"), std::string::npos) << e;
  EXPECT_NE(e.find("not consistently oriented"), std::string::npos) << e;
  e = error_of(dir, "kind = \"fluid_sphere\"\ncenter = [1.8, 1, 1]\nradius = 0.5\nspacing = 0.1");
  EXPECT_NE(e.find("particles[0].radius"), std::string::npos) << e;
  EXPECT_NE(e.find("outside the box"), std::string::npos) << e;
  e = error_of(dir, "kind = \"fluid_sphere\"\ncenter = [1, 1, 1]\nradius = 0.5");
  EXPECT_NE(e.find("particles[0].spacing"), std::string::npos) << e;
  e = error_of(dir, "kind = \"fluid_sphere\"\ncenter = [1, 1, 1]\nradius = 0.5\nspacing = 0.1\nmin = [0, 0, 0]");
  EXPECT_NE(e.find("particles[0].min"), std::string::npos) << e;
}

}  // namespace
}  // namespace swirl::scene
