// The live view's wire format (view/wire.hpp): frames and surface meshes
// round-trip within their quantisation, controls round-trip exactly, and
// every malformed control or mesh is refused with a reason.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "swirl/render/surface_mesh.hpp"
#include "swirl/view/wire.hpp"

namespace swirl::view {
namespace {

std::span<const std::uint8_t> bytes(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(Wire, AFrameRoundTripsWithinItsQuantisation) {
  FrameData f;
  f.step = 1234567890123ull;
  f.time = 0.125;
  f.lo = {-1, 0, 2};
  f.hi = {1, 3, 2.5f};
  f.colour_field = 3;
  for (int i = 0; i < 1000; ++i) {
    const float t = float(i) / 999.0f;
    f.x.push_back(-1 + 2 * t);
    f.y.push_back(3 * t * t);
    f.z.push_back(2 + 0.5f * (1 - t));
    f.colour.push_back(std::sin(float(i)));
  }
  f.x[7] = 5;  // outside the box: drawn on its face
  const std::string m = encode_frame(f);
  ASSERT_EQ(m.size(), kFrameHeaderBytes + 7 * 1000);
  const DecodedFrame d = decode_frame(bytes(m));
  EXPECT_EQ(d.step, f.step);
  EXPECT_EQ(d.time, f.time);
  EXPECT_EQ(d.colour_field, 3);
  ASSERT_EQ(d.x.size(), 1000u);
  for (std::size_t i = 0; i < 1000; ++i) {
    if (i == 7) {
      EXPECT_FLOAT_EQ(d.x[i], 1);
      continue;
    }
    // Half a quantisation step per axis (and float rounding).
    EXPECT_NEAR(d.x[i], f.x[i], 0.5 * 2 / 65535.0 + 1e-6);
    EXPECT_NEAR(d.y[i], f.y[i], 0.5 * 3 / 65535.0 + 1e-6);
    EXPECT_NEAR(d.z[i], f.z[i], 0.5 * 0.5 / 65535.0 + 1e-6);
    EXPECT_NEAR(d.colour[i], f.colour[i], 0.5 * (d.colour_max - d.colour_min) / 255.0 + 1e-6);
  }
  EXPECT_LE(d.colour_min, -0.99f);
  EXPECT_GE(d.colour_max, 0.99f);
}

TEST(Wire, ATruncatedOrForeignMessageIsNotAFrame) {
  FrameData f;
  f.x = f.y = f.z = {0.5f};
  f.hi = {1, 1, 1};
  const std::string m = encode_frame(f);
  EXPECT_THROW(decode_frame(bytes(m.substr(0, m.size() - 1))), std::invalid_argument);
  EXPECT_THROW(decode_frame(bytes(m.substr(0, 10))), std::invalid_argument);
  std::string other = m;
  other[0] = 'X';
  EXPECT_THROW(decode_frame(bytes(other)), std::invalid_argument);
}

TEST(Wire, ControlsRoundTrip) {
  control::Push push;
  push.point = {0.25f, -1, 2};
  push.velocity = {3, 0, -0.5f};
  push.radius = 0.1f;
  push.strength = 40;
  push.on = true;
  for (const Control& c : {Control{control::Pause{}}, Control{control::Resume{}}, Control{control::Step{}},
                           Control{control::Reset{}}, Control{control::Speed{60}}, Control{control::Colour{4}},
                           Control{push}, Control{control::Seek{70000}},
                           Control{control::Parameter{control::ParameterId::Gravity, {1, 0, -9.81f}}},
                           Control{control::Surface{true}}, Control{control::Surface{false}}}) {
    const Parsed p = parse_control(bytes(encode_control(c)));
    ASSERT_TRUE(p.control) << p.error;
    EXPECT_EQ(p.control->index(), c.index());
  }
  const Parsed p = parse_control(bytes(encode_control(push)));
  const auto& back = std::get<control::Push>(*p.control);
  EXPECT_EQ(back.point.y, -1);
  EXPECT_EQ(back.velocity.z, -0.5f);
  EXPECT_EQ(back.radius, 0.1f);
  EXPECT_TRUE(back.on);
  EXPECT_EQ(std::get<control::Seek>(*parse_control(bytes(encode_control(control::Seek{70000}))).control).frame, 70000u);
  const auto g = std::get<control::Parameter>(
      *parse_control(bytes(encode_control(control::Parameter{control::ParameterId::Gravity, {1, 0, -9.81f}}))).control);
  EXPECT_EQ(g.id, control::ParameterId::Gravity);
  EXPECT_EQ(g.value.z, -9.81f);
  EXPECT_EQ(encode_control(control::Surface{true}), std::string("\x0a\x01", 2));
  EXPECT_TRUE(std::get<control::Surface>(*parse_control(bytes(encode_control(control::Surface{true}))).control).on);
  EXPECT_FALSE(std::get<control::Surface>(*parse_control(bytes(encode_control(control::Surface{false}))).control).on);
}

TEST(Wire, MalformedControlsAreRefusedWithAReason) {
  control::Push push;
  push.radius = 1;
  std::string nan_push = encode_control(push);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_push.data() + 1, &nan, 4);
  std::string bad_on = encode_control(push);
  bad_on.back() = 7;
  push.radius = 0;
  const std::string zero_radius = encode_control(push);
  const std::string negative_speed = encode_control(control::Speed{-1});
  std::string unknown_parameter = encode_control(control::Parameter{control::ParameterId::Viscosity, {1, 0, 0}});
  unknown_parameter[1] = 3;
  std::string nan_parameter = encode_control(control::Parameter{control::ParameterId::Softening, {0, 0, 0}});
  std::memcpy(nan_parameter.data() + 2, &nan, 4);
  const std::string scalar_with_y = encode_control(control::Parameter{control::ParameterId::Viscosity, {1, 2, 0}});
  for (const auto& [message, reason] : std::vector<std::pair<std::string, std::string>>{
           {"", "empty"},
           {std::string(1, '\0'), "unknown control kind 0"},
           {std::string(1, char(99)), "unknown control kind 99"},
           {std::string(2, char(1)), "control kind 1 has 2 bytes, expected 1"},
           {std::string(1, char(5)), "control kind 5 has 1 bytes, expected 5"},
           {std::string(40, char(7)), "control kind 7 has 40 bytes, expected 34"},
           {nan_push, "not finite"},
           {bad_on, "'on' must be 0 or 1"},
           {zero_radius, "radius must be > 0"},
           {negative_speed, "must be finite and >= 0"},
           {std::string(3, char(8)), "control kind 8 has 3 bytes, expected 5"},
           {unknown_parameter, "unknown parameter 3"},
           {nan_parameter, "parameter: a value is not finite"},
           {scalar_with_y, "y and z must be 0"},
           {std::string(1, char(10)), "control kind 10 has 1 bytes, expected 2"},
           {std::string("\x0a\x01\x00", 3), "control kind 10 has 3 bytes, expected 2"},
           {std::string("\x0a\x02", 2), "surface: 'on' must be 0 or 1"},
           {std::string(1, char(11)), "unknown control kind 11"},
       }) {
    const Parsed p = parse_control(bytes(message));
    EXPECT_FALSE(p.control) << reason;
    EXPECT_NE(p.error.find(reason), std::string::npos) << p.error << " / expected: " << reason;
  }
}

// A ball of particles' surface (the colour field's mesh: closed, outward).
render::SurfaceMesh ball_mesh(double spacing, double radius) {
  std::vector<Vec3d> points;
  const int n = int(std::ceil(radius / spacing));
  for (int k = -n; k <= n; ++k)
    for (int j = -n; j <= n; ++j)
      for (int i = -n; i <= n; ++i)
        if (double(i * i + j * j + k * k) * spacing * spacing < radius * radius)
          points.push_back({0.3 + spacing * i, -0.2 + spacing * j, 1.0 + spacing * k});
  return render::reconstruct_surface(points, std::vector<double>{spacing * spacing * spacing},
                                     render::surface_params_for_spacing(spacing));
}

TEST(Wire, AMeshRoundTripsWithinItsQuantisation) {
  const render::SurfaceMesh mesh = ball_mesh(0.01, 0.08);
  ASSERT_GT(mesh.triangle_count(), 1000u);
  ASSERT_LE(mesh.vertices.size(), 65536u);
  const std::string m = encode_mesh(mesh, 1234, 0.5);
  EXPECT_EQ(m.size(), kMeshHeaderBytes + 6 * mesh.triangle_count() + 9 * mesh.vertices.size()) << "u16 indices";
  EXPECT_EQ(std::string(m.data(), 4), "SWVM");
  const DecodedMesh d = decode_mesh(bytes(m));
  EXPECT_EQ(d.step, 1234u);
  EXPECT_EQ(d.time, 0.5);
  EXPECT_EQ(d.index_bytes, 2u);
  EXPECT_EQ(d.iso, 0.5f);
  EXPECT_EQ(d.cell, float(mesh.cell_size));
  EXPECT_EQ(d.indices, mesh.indices);
  ASSERT_EQ(d.vertices.size(), mesh.vertices.size());
  double worst = 0, worst_normal = 0;
  for (std::size_t i = 0; i < d.vertices.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      const double step = (d.hi[std::size_t(a)] - d.lo[std::size_t(a)]) / 65535.0;
      worst = std::max(worst, std::abs(d.vertices[i][a] - mesh.vertices[i][a]) / step);
      worst_normal = std::max(worst_normal, double(std::abs(d.normals[i][a] - mesh.normals[i][a])));
    }
  // Half a step, plus the float rounding of lo + q·step near z = 1 (an ulp there is 0.05 of a step).
  EXPECT_LE(worst, 0.6) << "positions within half a quantisation step of the mesh's bounds";
  EXPECT_LE(worst_normal, 0.5 / 127 + 1e-6) << "normals within half a step of 1/127";
  EXPECT_EQ(d.lo[0], [&] { float lo = 1e9f; for (const auto& v : mesh.vertices) lo = std::min(lo, v.x); return lo; }());
  render::SurfaceMesh back;
  back.vertices = d.vertices;
  back.indices = d.indices;
  EXPECT_NEAR(render::enclosed_volume(back) / render::enclosed_volume(mesh), 1.0, 1e-4);

  // No surface (no fluid): a header alone.
  const DecodedMesh empty = decode_mesh(bytes(encode_mesh(render::SurfaceMesh{}, 7, 0.25)));
  EXPECT_EQ(empty.vertices.size(), 0u);
  EXPECT_EQ(empty.triangle_count(), 0u);
  EXPECT_EQ(empty.step, 7u);
}

TEST(Wire, AMeshOfMoreThan65536VerticesHasU32Indices) {
  render::SurfaceMesh mesh;
  for (int i = 0; i < 70000; ++i) {
    mesh.vertices.push_back({float(i % 100), float(i / 100), 0.0f});
    mesh.normals.push_back({0.0f, 0.0f, 1.0f});
  }
  mesh.indices = {0, 1, 69999, 69998, 69999, 1};
  const std::string m = encode_mesh(mesh, 1, 0);
  EXPECT_EQ(m.size(), kMeshHeaderBytes + 12 * 2 + 9 * 70000);
  const DecodedMesh d = decode_mesh(bytes(m));
  EXPECT_EQ(d.index_bytes, 4u);
  EXPECT_EQ(d.indices, mesh.indices);
  EXPECT_EQ(d.vertices[69999].y, 699.0f);
  EXPECT_EQ(d.normals[5].z, 1.0f);
}

TEST(Wire, MalformedMeshesAreRefusedWithAReason) {
  const std::string good = encode_mesh(ball_mesh(0.01, 0.04), 3, 0.1);
  ASSERT_NO_THROW(decode_mesh(bytes(good)));
  const auto with = [&](std::size_t at, const auto& value) {
    std::string m = good;
    std::memcpy(m.data() + at, &value, sizeof(value));
    return m;
  };
  std::string wide = good;  // 2-byte indices claimed for 70 000 vertices
  const std::uint32_t many = 70000;
  std::memcpy(wide.data() + 24, &many, 4);
  std::string out_of_range = good;
  const std::uint16_t beyond = 60000;
  std::memcpy(out_of_range.data() + kMeshHeaderBytes + 2 * 4, &beyond, 2);  // index 4: triangle 1's second
  for (const auto& [message, reason] : std::vector<std::pair<std::string, std::string>>{
           {good.substr(0, 20), "shorter than the header"},
           {good.substr(0, good.size() - 1), "bytes for"},
           {good + "x", "bytes for"},
           {with(0, std::uint32_t{0x46565753u}), "not a swirl mesh"},
           {with(4, std::uint16_t{2}), "version 2, this reader knows 1"},
           {with(6, std::uint16_t{3}), "3-byte indices"},
           {wide, "2-byte indices for 70000 vertices"},
           {with(36, std::numeric_limits<float>::quiet_NaN()), "bounds are not finite"},
           {with(32, 1e9f), "lo > hi"},
           {out_of_range, "triangle 1 names vertex 60000"},
       }) {
    try {
      decode_mesh(bytes(message));
      ADD_FAILURE() << "decoded: " << reason;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what() << " / expected: " << reason;
    }
  }
  render::SurfaceMesh bad;
  bad.vertices = {{0, 0, 0}};
  bad.normals = {{0, 0, 1}};
  bad.indices = {0, 0, 1};
  EXPECT_THROW(encode_mesh(bad, 0, 0), std::invalid_argument);
  bad.indices.clear();
  bad.vertices[0].x = std::numeric_limits<float>::infinity();
  EXPECT_THROW(encode_mesh(bad, 0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::view
