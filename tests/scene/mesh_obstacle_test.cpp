// [[particles]] kind = "obstacle_mesh": triangles from STL (ASCII, binary) and
// OBJ files through Assimp (io/mesh_file.hpp), placed by scale, rotate_deg and
// translate, and sampled at the fluid's spacing (scene/mesh_sampling.hpp):
// the three formats give the same particles; on a unit cube the count, every
// point on the surface, no point twice, every surface point within a spacing
// of one; the placement; and every refusal names the scene file, the key and
// the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "io/io_test_util.hpp"
#include "scene/mesh_test_util.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/io/mesh_file.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/scene/mesh_sampling.hpp"
#include "swirl/scene/validate.hpp"

namespace swirl::scene {
namespace {

namespace fs = std::filesystem;
using io::test::TempDir;

// A tank [0, 2]³ of DFSPH fluid (a block at `spacing`) with one mesh obstacle of `keys`.
std::string mesh_scene(const std::string& keys, double spacing = 0.1) {
  return fmt::format(R"([simulation]
precision = "double"
dt = 0.001
steps = 1
[box]
min = [0, 0, 0]
max = [2, 2, 2]
[sph]
method = "dfsph"
neighbours = 30
[[particles]]
kind = "fluid_block"
min = [1.5, 1.5, 1.5]
max = [2, 2, 2]
spacing = {}
[[particles]]
kind = "obstacle_mesh"
{}
)",
                     spacing, keys);
}

std::vector<Vec3d> sampled(const Scene& s) { return obstacle_points(std::get<ObstacleSource>(s.sources.at(1))); }

Scene load_with(const TempDir& dir, const std::string& keys, double spacing = 0.1) {
  io::test::spit(dir / "scene.toml", mesh_scene(keys, spacing));
  return load_scene(dir / "scene.toml");
}

std::string error_of(const TempDir& dir, const std::string& keys, double spacing = 0.1) {
  try {
    (void)load_with(dir, keys, spacing);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(accepted)";
}

// Distance from p to the surface of [lo, hi]³ (p inside or on it).
double to_cube_surface(const Vec3d& p, double lo, double hi) {
  double d = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) d = std::min({d, std::abs(p[a] - lo), std::abs(p[a] - hi)});
  return d;
}

TEST(MeshObstacle, StlAsciiStlBinaryAndObjGiveTheSameParticles) {
  TempDir dir;
  const test::Mesh cube = test::unit_cube();
  io::test::spit(dir / "cube_ascii.stl", test::ascii_stl(cube));
  io::test::spit(dir / "cube_binary.STL", test::binary_stl(cube));
  io::test::spit(dir / "cube.obj", test::obj(cube));
  const auto ascii = sampled(load_with(dir, "file = \"cube_ascii.stl\"\ntranslate = [0.5, 0.5, 0.2]"));
  const auto binary = sampled(load_with(dir, "file = \"cube_binary.STL\"\ntranslate = [0.5, 0.5, 0.2]"));
  const auto wavefront = sampled(load_with(dir, "file = \"cube.obj\"\ntranslate = [0.5, 0.5, 0.2]"));
  ASSERT_FALSE(ascii.empty());
  EXPECT_EQ(ascii, binary);
  EXPECT_EQ(ascii, wavefront);
  // An OBJ naming a material library: not opened (Assimp sees no file system), the same particles.
  io::test::spit(dir / "cube.mtl", "newmtl red\nKd 1 0 0\n");
  io::test::spit(dir / "cube_mtl.obj", "mtllib cube.mtl\nusemtl red\n" + test::obj(cube));
  EXPECT_EQ(sampled(load_with(dir, "file = \"cube_mtl.obj\"\ntranslate = [0.5, 0.5, 0.2]")), ascii);
  // The reader merged the corners: 8 vertices, 12 triangles, each corner once.
  const io::TriangleMesh m = io::read_triangle_mesh(dir / "cube_ascii.stl");
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
}

TEST(MeshObstacle, AUnitCubeIsSampledOnItsSurfaceWithinASpacingEverywhereAndNoPointTwice) {
  TempDir dir;
  io::test::spit(dir / "cube.stl", test::ascii_stl(test::unit_cube()));
  const double s = 0.1;
  const Scene scene = load_with(dir, "file = \"cube.stl\"\ntranslate = [0.5, 0.5, 0.2]", s);
  std::vector<Vec3d> points = sampled(scene);
  for (auto& p : points) p = p - Vec3d{0.5, 0.5, 0.2};  // back to [0, 1]³ (exact: the shifts are dyadic-free but
                                                         // the test only needs round-off)
  // 8 corners; 12 edges of 9 inner points and 6 face diagonals of 14
  // (ceil(√2/0.1) = 15 intervals); each of the 12 right triangles in rows
  // parallel to its hypotenuse, ceil(0.707/0.1) = 8 rows, 46 inner points.
  EXPECT_EQ(points.size(), 8u + 12u * 9u + 6u * 14u + 12u * 46u);
  EXPECT_EQ(points.size(), count_particles(scene) - 5u * 5u * 5u);  // the count validation used
  // Between the area's 600 s² cells and 1.5 times that.
  EXPECT_GE(points.size(), 600u);
  EXPECT_LE(points.size(), 900u);
  double nearest_min = 1;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3d& p = points[i];
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(p[a], -1e-12);
      EXPECT_LE(p[a], 1 + 1e-12);
    }
    EXPECT_LT(to_cube_surface(p, 0, 1), 1e-12) << p.x << " " << p.y << " " << p.z;
    for (std::size_t j = 0; j < i; ++j) nearest_min = std::min(nearest_min, norm(p - points[j]));
  }
  // No point twice (shared edges and corners once), none much closer than the spacing.
  EXPECT_GT(nearest_min, 0.25 * s);
  // Every point of the surface within a spacing of a sample: a 41 × 41 grid on each face.
  double gap = 0;
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j <= 40; ++j) {
        Vec3d q;
        const int axis = face / 2;
        q[axis] = face % 2;
        q[(axis + 1) % 3] = i / 40.0;
        q[(axis + 2) % 3] = j / 40.0;
        double nearest = 1e9;
        for (const auto& p : points) nearest = std::min(nearest, norm(q - p));
        gap = std::max(gap, nearest);
      }
  std::printf("unit cube at s = %g: %zu points, nearest pair %.3f s, largest gap %.3f s\n", s, points.size(),
              nearest_min / s, gap / s);
  EXPECT_LE(gap, s);
}

TEST(MeshObstacle, TheSteppedBlockIsSampledOnItsEdgesAndWithinASpacingOfEverySurfacePoint) {
  // The example's block (mm, scale 0.001) at s = 0.02: its sharp edges carry points at most s apart.
  TempDir dir;
  io::test::spit(dir / "block.stl", test::binary_stl(test::step_block()));
  const double s = 0.02;
  const auto points = sampled(load_with(dir, "file = \"block.stl\"\nscale = 0.001\ntranslate = [0.5, 0.5, 0.0]", s));
  // The step's outer edges along y, at (x, z) = (0.12, 0.16) and (0.24, 0.08): 0.2 long, 11 points each.
  for (const auto& [x, z] : {std::pair{0.62, 0.16}, std::pair{0.74, 0.08}}) {
    int on = 0;
    for (const auto& p : points) on += std::abs(p.x - x) < 1e-9 && std::abs(p.z - z) < 1e-9 ? 1 : 0;
    EXPECT_EQ(on, 11) << x << " " << z;
  }
  std::set<std::tuple<long, long, long>> seen;
  for (const auto& p : points) seen.insert({std::lround(p.x * 1e7), std::lround(p.y * 1e7), std::lround(p.z * 1e7)});
  EXPECT_EQ(seen.size(), points.size());
  // Surface points of the two step tops and the risers, each within s of a sample.
  double gap = 0;
  const auto nearest = [&](const Vec3d& q) {
    double d = 1e9;
    for (const auto& p : points) d = std::min(d, norm(q - p));
    return d;
  };
  for (int i = 0; i <= 24; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double x = 0.5 + 0.24 * i / 24.0, y = 0.5 + 0.2 * j / 20.0;
      gap = std::max(gap, nearest({x, y, x <= 0.62 ? 0.16 : 0.08}));      // the tops
      gap = std::max(gap, nearest({x, y, 0.0}));                          // the bottom
      gap = std::max(gap, nearest({x, 0.5, 0.16 * i / 24.0 * (x <= 0.62 ? 1 : 0.5)}));  // the near side
    }
  std::printf("stepped block at s = %g: %zu points, largest gap %.3f s\n", s, points.size(), gap / s);
  EXPECT_LE(gap, s);
}

TEST(MeshObstacle, ScaleRotationAndTranslationPlaceTheVertices) {
  ObstacleSource o;
  o.shape = ObstacleSource::Shape::Mesh;
  o.mesh = std::make_shared<io::TriangleMesh>(io::TriangleMesh{{{1, 0, 0}, {0, 2, 0}, {0, 0, 3}}, {{{0, 1, 2}}}});
  o.scale = 2;
  o.rotate_deg = {0, 0, 90};  // about z: x → y, y → −x
  o.translate = {1, 1, 1};
  const auto x = placed_vertices(o);
  ASSERT_EQ(x.size(), 3u);
  // Quarter turns are exact.
  EXPECT_EQ(x[0], (Vec3d{1, 3, 1}));
  EXPECT_EQ(x[1], (Vec3d{-3, 1, 1}));
  EXPECT_EQ(x[2], (Vec3d{1, 1, 7}));
  o.rotate_deg = {90, 0, -180};  // about x: y → z; then about z: x → −x
  o.scale = 1;
  o.translate = {};
  EXPECT_EQ(placed_vertices(o)[0], (Vec3d{-1, 0, 0}));
  EXPECT_EQ(placed_vertices(o)[1], (Vec3d{0, 0, 2}));
  o.rotate_deg = {0, 30, 0};  // about y: z → x by 30°
  EXPECT_NEAR(norm(placed_vertices(o)[2] - Vec3d{1.5, 0, 3 * std::sqrt(0.75)}), 0, 1e-15);
  // Unplaced, the file's coordinates bit for bit.
  o.rotate_deg = {};
  EXPECT_EQ(placed_vertices(o), o.mesh->vertices);
}

TEST(MeshObstacle, TheSampleIsTheSameEveryTimeAndTheSavedSceneNamesTheFileAbsolutely) {
  TempDir dir;
  io::test::spit(dir / "block.obj", test::obj(test::step_block(0.001)));
  const Scene a = load_with(dir, "file = \"block.obj\"\ntranslate = [0.3, 0.3, 0.0]\nrotate_deg = [0, 0, 30]", 0.02);
  const Scene b = load_with(dir, "file = \"block.obj\"\ntranslate = [0.3, 0.3, 0.0]\nrotate_deg = [0, 0, 30]", 0.02);
  EXPECT_EQ(sampled(a), sampled(b));
  const ParticleSet<double> p = make_particles<double>(a);
  const std::size_t k = p.find_int_field(kKindField);
  ASSERT_NE(k, ParticleSet<double>::npos);
  std::size_t boundary = 0;
  for (std::size_t i = 0; i < p.size(); ++i) boundary += is_boundary(p.int_field(k)[i]) ? 1 : 0;
  EXPECT_EQ(boundary, sampled(a).size());
  const std::string absolute = (dir / "block.obj").lexically_normal().string();
  EXPECT_EQ(std::get<ObstacleSource>(a.sources[1]).file, absolute);
  EXPECT_NE(a.toml.find(absolute), std::string::npos);
  // The saved TOML loads again from elsewhere, to the same hash.
  EXPECT_EQ(scene_hash(parse_scene(a.toml, "/elsewhere/scene.toml")), scene_hash(a));
  // The placement is part of the hash.
  const Scene c = load_with(dir, "file = \"block.obj\"\ntranslate = [0.3, 0.3, 0.0]\nrotate_deg = [0, 0, 31]", 0.02);
  EXPECT_NE(scene_hash(c), scene_hash(a));
}

TEST(MeshObstacle, BadMeshesAreRefusedNamingTheSceneFileTheKeyAndTheReason) {
  TempDir dir;
  const std::string scene = (dir / "scene.toml").string();
  const auto expect = [&](const std::string& keys, const std::string& needle, double spacing = 0.1) {
    const std::string message = error_of(dir, keys, spacing);
    EXPECT_NE(message.find(scene), std::string::npos) << message;
    EXPECT_NE(message.find(needle), std::string::npos) << message;
    if (std::getenv("SWIRL_SHOW_MESSAGES")) std::printf("%s\n", message.c_str());
  };
  expect("file = \"missing.stl\"", "particles[1].file: " + (dir / "missing.stl").string() + ": no such file");
  expect("translate = [0, 0, 0]", "particles[1].file: missing");

  io::test::spit(dir / "empty.stl", "");
  expect("file = \"empty.stl\"", "empty.stl: the file is empty");

  io::test::spit(dir / "junk.stl", "solid junk\n  facet normal 0 0 1\n    outer loop\n      vertex 1 2\n");
  expect("file = \"junk.stl\"", "junk.stl: not a valid STL file (Assimp: ");
  // A binary STL whose header promises more triangles than it holds.
  std::string cut = test::binary_stl(test::unit_cube());
  cut.resize(cut.size() - 100);
  io::test::spit(dir / "cut.stl", cut);
  expect("file = \"cut.stl\"", "cut.stl: not a valid STL file (Assimp: ");
  expect("file = \"cut.stl\"", "representation for " + (dir / "cut.stl").string() + ".)");
  io::test::spit(dir / "junk.obj", "this is not\x01\x02 an obj file\nf 1 2 3\n");
  expect("file = \"junk.obj\"", "junk.obj: ");

  io::test::spit(dir / "comments.obj", "# no vertices\n# and no faces\n");
  expect("file = \"comments.obj\"", "comments.obj: the mesh is empty (no vertices)");
  io::test::spit(dir / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expect("file = \"points.obj\"", "points.obj: the mesh ");
  io::test::spit(dir / "lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
  expect("file = \"lines.obj\"", "lines.obj: the mesh has no triangles");
  io::test::spit(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nf 1 2 2\n");
  expect("file = \"flat.obj\"", "flat.obj: the mesh has no triangles");

  io::test::spit(dir / "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  expect("file = \"nan.obj\"", "nan.obj: vertex 1 of mesh 0 is (nan, 0, 0): coordinates must be finite");

  io::test::spit(dir / "cube.ply", test::ascii_stl(test::unit_cube()));
  expect("file = \"cube.ply\"", "cube.ply: not a mesh swirl reads: the name must end in .stl");

  io::test::spit(dir / "cube.stl", test::ascii_stl(test::unit_cube()));
  expect("file = \"cube.stl\"\ntranslate = [1.5, 0.5, 0.5]",
         "particles[1].translate: " + (dir / "cube.stl").string() + ": the placed mesh reaches outside the box");
  expect("file = \"cube.stl\"\nscale = 1e308\ntranslate = [1e308, 0, 0]", "particles[1].scale: " + (dir / "cube.stl").string() + ": vertex 2 lands at (inf, ");
  expect("file = \"cube.stl\"\nscale = 0", "particles[1].scale: must be > 0");
  // Too many particles: 2^24 per mesh. At 1 mm the cube's 6 m² would take
  // about 7.5 million; at 0.2 mm about 190 million (the exact count is not
  // even attempted past 16 times the limit).
  EXPECT_EQ(error_of(dir, "file = \"cube.stl\"\ntranslate = [0.5, 0.5, 0.5]\nspacing = 0.001"), "(accepted)");
  expect("file = \"cube.stl\"\ntranslate = [0.5, 0.5, 0.5]\nspacing = 0.0004",
         "particles[1].spacing: " + (dir / "cube.stl").string() + ": the mesh's 12 triangles spanning");
  expect("file = \"cube.stl\"\ntranslate = [0.5, 0.5, 0.5]\nspacing = 0.0004", "more than the limit of 16777216 (2^24)");
  expect("file = \"cube.stl\"\ntranslate = [0.5, 0.5, 0.5]\nspacing = 0.00005", "up to about ");
}

TEST(MeshObstacle, AMeshBuiltInCodeWithBadIndicesIsRefusedBeforeItIsSampled) {
  TempDir dir;
  io::test::spit(dir / "cube.stl", test::ascii_stl(test::unit_cube()));
  Scene s = load_with(dir, "file = \"cube.stl\"\ntranslate = [0.5, 0.5, 0.5]");
  auto& o = std::get<ObstacleSource>(s.sources[1]);
  auto bad = std::make_shared<io::TriangleMesh>(*o.mesh);
  bad->triangles.push_back({0, 1, 8});  // the cube has vertices 0 to 7
  o.mesh = bad;
  EXPECT_EQ(mesh_point_count(o), 0u);
  EXPECT_THROW(validate(s), SceneError);
  EXPECT_THROW((void)make_particles<double>(s), SceneError);
  o.mesh.reset();
  EXPECT_THROW(validate(s), SceneError);
  EXPECT_THROW((void)make_particles<double>(s), SceneError);
}

}  // namespace
}  // namespace swirl::scene
