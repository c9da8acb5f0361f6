// The fluid surface: the colour field's iso-surface on particles (closed,
// oriented, the right volume and height, bit-identical for any thread count),
// its PLY and OBJ files, and a frame's boundary particles left out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include "render/render_test_util.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/render/fluid_surface.hpp"
#include "swirl/render/obj.hpp"
#include "swirl/render/ply.hpp"
#include "swirl/render/surface_mesh.hpp"

namespace swirl::render {
namespace {

// Lattice points s·(i, j, k) inside a sphere of `radius` around `centre`.
std::vector<Vec3d> lattice_sphere(double s, double radius, Vec3d centre) {
  std::vector<Vec3d> out;
  const int n = static_cast<int>(std::ceil(radius / s)) + 1;
  for (int k = -n; k <= n; ++k)
    for (int j = -n; j <= n; ++j)
      for (int i = -n; i <= n; ++i) {
        const Vec3d d{s * i, s * j, s * k};
        if (dot(d, d) < radius * radius) out.push_back(centre + d);
      }
  return out;
}

// Every undirected edge in exactly two triangles, every directed edge in one
// (a closed, consistently oriented mesh); no degenerate index triple.
void expect_closed(const SurfaceMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t* v = &mesh.indices[3 * t];
    ASSERT_TRUE(v[0] != v[1] && v[1] != v[2] && v[0] != v[2]) << "triangle " << t;
    for (int e = 0; e < 3; ++e) ++directed[{v[e], v[(e + 1) % 3]}];
  }
  std::size_t bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "edges not shared by exactly two oppositely oriented triangles, of " << directed.size();
}

TEST(SurfaceMesh, SphereOfFluidIsClosedAndHoldsTheFluidsVolume) {
  const double s = 0.01, radius = 12 * s;
  const auto positions = lattice_sphere(s, radius, {0.3, -0.2, 0.5});
  const std::vector<double> volume{s * s * s};
  const SurfaceMesh mesh = reconstruct_surface(positions, volume, surface_params_for_spacing(s));
  ASSERT_GT(mesh.triangle_count(), 1000u);
  expect_closed(mesh);
  const double fluid = static_cast<double>(positions.size()) * volume[0];
  const double enclosed = enclosed_volume(mesh);
  std::printf("sphere of %zu particles: mesh volume / fluid volume = %.5f, %zu triangles\n", positions.size(),
              enclosed / fluid, mesh.triangle_count());
  EXPECT_NEAR(enclosed / fluid, 1.0, 0.02) << positions.size() << " particles, fluid " << fluid << " m³, mesh "
                                           << enclosed << " m³";
  // Normals point outwards: away from the centre.
  for (std::size_t v = 0; v < mesh.vertices.size(); v += 97) {
    const Vec3d d = mesh.vertices[v].cast<double>() - Vec3d{0.3, -0.2, 0.5};
    EXPECT_GT(dot(d, mesh.normals[v].cast<double>()), 0.9 * norm(d)) << v;
  }
}

TEST(SurfaceMesh, FlatSurfaceLiesHalfASpacingAboveTheTopLayer) {
  // A slab 24 × 24 × 8 particles at s·(i + ½): the fluid fills z in [0, 8s].
  const double s = 0.02;
  std::vector<Vec3d> positions;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 24; ++j)
      for (int i = 0; i < 24; ++i) positions.push_back({s * (i + 0.5), s * (j + 0.5), s * (k + 0.5)});
  const std::vector<double> volume{s * s * s};
  const SurfaceMesh mesh = reconstruct_surface(positions, volume, surface_params_for_spacing(s));
  expect_closed(mesh);
  // Top and bottom faces, away from the rounded edges: at 8s and 0 within 2 % of s.
  int top = 0, bottom = 0;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3d p = mesh.vertices[v].cast<double>();
    if (std::abs(p.x - 12 * s) > 6 * s || std::abs(p.y - 12 * s) > 6 * s) continue;
    if (p.z > 4 * s) {
      EXPECT_NEAR(p.z, 8 * s, 0.02 * s) << v;
      EXPECT_GT(mesh.normals[v].z, 0.999f);
      ++top;
    } else {
      EXPECT_NEAR(p.z, 0.0, 0.02 * s) << v;
      EXPECT_LT(mesh.normals[v].z, -0.999f);
      ++bottom;
    }
  }
  EXPECT_GT(top, 100);
  EXPECT_GT(bottom, 100);
  // The slab's volume, less what its rounded edges and corners lose.
  const double fluid = static_cast<double>(positions.size()) * volume[0];
  std::printf("slab: mesh volume / fluid volume = %.5f\n", enclosed_volume(mesh) / fluid);
  EXPECT_NEAR(enclosed_volume(mesh) / fluid, 1.0, 0.03);
}

// The slow twin of color_field's slab-wise accumulation: at every grid node,
// c = Σ_j V_j W(|x − x_j|, R) over all particles, poly6 W = 315/(64πR³)(1 − r²/R²)³,
// summed directly in double. The fast field stores floats: equal to float
// rounding of the largest value.
TEST(SurfaceMesh, ColorFieldEqualsTheDirectSumAtEveryNode) {
  const double s = 0.01;
  std::vector<Vec3d> positions = lattice_sphere(s, 4 * s, {0.3, -0.2, 0.1});
  std::vector<double> volumes(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double u = std::sin(78.233 * static_cast<double>(i + 1));
    positions[i] += Vec3d{0.4 * u * s, -0.3 * u * s, 0.2 * u * s};
    volumes[i] = s * s * s * (1.0 + 0.2 * u);
  }
  const SurfaceParams params = surface_params_for_spacing(s, 2.0, 0.5);
  const ColorField field = color_field(positions, volumes, params);
  ASSERT_GT(field.nx * field.ny * field.nz, 1000);
  const double R = params.kernel_radius;
  const double norm = 315.0 / (64.0 * std::numbers::pi * R * R * R);
  double largest = 0, worst = 0;
  for (int k = 0; k < field.nz; ++k)
    for (int j = 0; j < field.ny; ++j)
      for (int i = 0; i < field.nx; ++i) {
        const Vec3d x = field.origin + Vec3d{field.cell * i, field.cell * j, field.cell * k};
        double c = 0;
        for (std::size_t p = 0; p < positions.size(); ++p) {
          const Vec3d d = x - positions[p];
          const double q = 1.0 - dot(d, d) / (R * R);
          if (q > 0) c += volumes[p] * norm * q * q * q;
        }
        largest = std::max(largest, c);
        worst = std::max(worst, std::abs(c - static_cast<double>(field.at(i, j, k))));
      }
  EXPECT_GT(largest, 0.5);  // the blob's inside is near 1
  EXPECT_LT(worst, 1e-5 * largest) << "largest node value " << largest;
}

TEST(SurfaceMesh, BitIdenticalForOneAndTwoThreads) {
  // A jittered blob, with per-particle volumes.
  const double s = 0.01;
  std::vector<Vec3d> positions = lattice_sphere(s, 9 * s, {0, 0, 0});
  std::vector<double> volumes(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double u = std::sin(12.9898 * static_cast<double>(i)) * 0.3;
    positions[i] += Vec3d{u * s, -u * 0.5 * s, u * 0.7 * s};
    volumes[i] = s * s * s * (1.0 + 0.1 * u);
  }
  const int saved = parallel::thread_count();
  std::vector<SurfaceMesh> meshes;
  for (int threads : {1, 2, 3}) {
    parallel::set_thread_count(threads);
    meshes.push_back(reconstruct_surface(positions, volumes, surface_params_for_spacing(s, 2.0, 0.4)));
  }
  parallel::set_thread_count(saved);
  ASSERT_GT(meshes[0].triangle_count(), 100u);
  for (std::size_t m = 1; m < meshes.size(); ++m) {
    ASSERT_EQ(meshes[m].vertices.size(), meshes[0].vertices.size());
    ASSERT_EQ(meshes[m].indices, meshes[0].indices);
    EXPECT_EQ(std::memcmp(meshes[m].vertices.data(), meshes[0].vertices.data(), meshes[0].vertices.size() * sizeof(Vec3<float>)), 0);
    EXPECT_EQ(std::memcmp(meshes[m].normals.data(), meshes[0].normals.data(), meshes[0].normals.size() * sizeof(Vec3<float>)), 0);
    EXPECT_EQ(encode_ply(meshes[m], 1.5), encode_ply(meshes[0], 1.5));
  }
}

TEST(SurfaceMesh, CoarsensTheGridToStayWithinMaxNodes) {
  const double s = 0.01;
  auto positions = lattice_sphere(s, 5 * s, {0, 0, 0});
  positions.push_back({1.0, 1.0, 1.0});  // a lone far particle stretches the bounds
  SurfaceParams params = surface_params_for_spacing(s);
  params.max_nodes = 1u << 20;
  const ColorField field = color_field(positions, std::vector<double>{s * s * s}, params);
  EXPECT_LE(field.value.size(), params.max_nodes);
  EXPECT_GT(field.cell, params.cell_size);
  EXPECT_TRUE(reconstruct_surface({}, std::vector<double>{1.0}, params).indices.empty());
  EXPECT_THROW(color_field(positions, std::vector<double>{1, 2}, params), std::invalid_argument);
  params.iso = 1.0;
  EXPECT_THROW(reconstruct_surface(positions, std::vector<double>{1.0}, params), std::invalid_argument);
}

TEST(SurfacePly, RoundTripsItsHeaderAndData) {
  test::TempDir dir;
  const double s = 0.01;
  const SurfaceMesh mesh =
      reconstruct_surface(lattice_sphere(s, 5 * s, {0.1, 0.2, 0.3}), std::vector<double>{s * s * s}, surface_params_for_spacing(s));
  const auto path = dir.path / "surface_000007.ply";
  write_ply(path, mesh, 0.125);
  const std::string bytes = io::read_text_file(path);
  const std::string header = bytes.substr(0, bytes.find("end_header\n") + 11);
  EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(header.find("element vertex " + std::to_string(mesh.vertices.size()) + "\n"), std::string::npos) << header;
  EXPECT_NE(header.find("element face " + std::to_string(mesh.triangle_count()) + "\n"), std::string::npos) << header;
  EXPECT_NE(header.find("property list uchar uint vertex_indices\n"), std::string::npos);
  EXPECT_EQ(bytes.size(), header.size() + 24 * mesh.vertices.size() + 13 * mesh.triangle_count());
  // The first vertex's x, by hand (little-endian float).
  float x0 = 0;
  unsigned char le[4];
  std::memcpy(le, bytes.data() + header.size(), 4);
  const std::uint32_t bits = le[0] | (le[1] << 8) | (le[2] << 16) | (std::uint32_t{le[3]} << 24);
  std::memcpy(&x0, &bits, 4);
  EXPECT_EQ(x0, mesh.vertices[0].x);
  EXPECT_EQ(static_cast<unsigned char>(bytes[header.size() + 24 * mesh.vertices.size()]), 3u);

  const PlyFile back = read_ply(path);
  EXPECT_EQ(back.time, 0.125);
  EXPECT_EQ(back.mesh.iso, mesh.iso);
  EXPECT_EQ(back.mesh.vertices, mesh.vertices);
  EXPECT_EQ(back.mesh.normals, mesh.normals);
  EXPECT_EQ(back.mesh.indices, mesh.indices);
  EXPECT_DOUBLE_EQ(enclosed_volume(back.mesh), enclosed_volume(mesh));

  // A truncated file is refused with its name.
  io::write_file_atomic(dir.path / "cut.ply", bytes.substr(0, bytes.size() - 5));
  try {
    read_ply(dir.path / "cut.ply");
    FAIL() << "read a truncated file";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.ply"), std::string::npos) << e.what();
  }
}

TEST(SurfaceObj, ReadsBackTheMeshThePlyHolds) {
  test::TempDir dir;
  const double s = 0.01;
  const SurfaceMesh mesh =
      reconstruct_surface(lattice_sphere(s, 5 * s, {0.1, 0.2, 0.3}), std::vector<double>{s * s * s}, surface_params_for_spacing(s));
  ASSERT_GT(mesh.triangle_count(), 100u);
  write_ply(dir.path / "surface_000003.ply", mesh, 0.375);
  write_obj(dir.path / "surface_000003.obj", mesh, 0.375);
  const std::string text = io::read_text_file(dir.path / "surface_000003.obj");
  EXPECT_EQ(text.rfind("# swirl fluid surface", 0), 0u) << text.substr(0, 200);
  EXPECT_NE(text.find("\nf 1//1 "), std::string::npos) << "faces are 1-based v//vn pairs";
  const PlyFile ply = read_ply(dir.path / "surface_000003.ply");
  const ObjFile obj = read_obj(dir.path / "surface_000003.obj");
  EXPECT_EQ(obj.time, 0.375);
  EXPECT_EQ(obj.mesh.iso, mesh.iso);
  EXPECT_EQ(obj.mesh.vertices.size(), ply.mesh.vertices.size());
  EXPECT_EQ(obj.mesh.triangle_count(), ply.mesh.triangle_count());
  // Exactly: the shortest decimal form of a float reads back to that float.
  EXPECT_EQ(obj.mesh.vertices, ply.mesh.vertices);
  EXPECT_EQ(obj.mesh.normals, ply.mesh.normals);
  EXPECT_EQ(obj.mesh.indices, ply.mesh.indices);
  EXPECT_EQ(enclosed_volume(obj.mesh), enclosed_volume(ply.mesh));
  expect_closed(obj.mesh);
}

TEST(SurfaceObj, RefusesWhatItDidNotWriteNamingTheFileAndLine) {
  test::TempDir dir;
  const auto refused = [&](const std::string& name, const std::string& text, const std::string& why) {
    io::write_file_atomic(dir.path / name, text);
    try {
      read_obj(dir.path / name);
      ADD_FAILURE() << name << " was read";
    } catch (const io::IoError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n";
  refused("bad_number.obj", "v 0 0 zero\n", "bad_number.obj:1:");
  refused("quad.obj", tri + "v 1 1 0\nvn 0 0 1\nf 1//1 2//2 4//4 3//3\n", "not a triangle");
  refused("range.obj", tri + "f 1//1 2//2 9//9\n", "names vertex 9 of 3");
  refused("mixed.obj", tri + "f 1//1 2//3 3//3\n", "vertex 2 with normal 3");
  refused("uv.obj", tri + "f 1/1/1 2/2/2 3/3/3\n", "v//vn pairs");
  refused("normals.obj", "v 0 0 0\nv 1 0 0\nvn 0 0 1\n", "1 normals for 2 vertices");
  refused("material.obj", "mtllib water.mtl\n" + tri, "unexpected record 'mtllib'");
  io::write_file_atomic(dir.path / "ok.obj", tri + "f 1//1 2//2 3//3\n");
  EXPECT_EQ(read_obj(dir.path / "ok.obj").mesh.triangle_count(), 1u);
}

// A frame with boundary particles (kind 1: a wall's layer) and a block of
// water: the surface is the water's alone, as if the wall were not there.
TEST(FluidSurface, LeavesABoundaryParticlesOut) {
  const double s = 0.01, rho0 = 1000, m = rho0 * s * s * s;
  Frame water;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) water.positions.push_back({s * i, s * j, s * (k + 1)});
  water.mass.assign(water.positions.size(), m);
  Frame walled = water;
  walled.kind.assign(water.positions.size(), 0);
  for (int j = -3; j < 11; ++j)
    for (int i = -3; i < 11; ++i) {  // a floor under the water, wider than it
      walled.positions.push_back({s * i, s * j, 0.0});
      walled.mass.push_back(0.7 * m);  // a volume weight, not a fluid's mass
      walled.kind.push_back(1);
    }
  FluidSurface settings;
  settings.rest_density = rho0;
  const SurfaceMesh a = frame_surface(water, settings), b = frame_surface(walled, settings);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.indices, b.indices);
  // A cube of 8³ spacings: its rounded edges and corners lose 5.6 % (measured 0.944).
  EXPECT_NEAR(enclosed_volume(b) / (512 * s * s * s), 0.944, 0.01);
  // Without its kinds the floor would be water too: a larger, different mesh.
  Frame kindless = walled;
  kindless.kind.clear();
  EXPECT_GT(enclosed_volume(frame_surface(kindless, settings)), 1.1 * enclosed_volume(b));
}

}  // namespace
}  // namespace swirl::render
