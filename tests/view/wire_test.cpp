// The live view's wire format (view/wire.hpp): frames round-trip within their
// quantisation, controls round-trip exactly, and every malformed control is
// refused with a reason.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

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
                           Control{control::Parameter{control::ParameterId::Gravity, {1, 0, -9.81f}}}}) {
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
       }) {
    const Parsed p = parse_control(bytes(message));
    EXPECT_FALSE(p.control) << reason;
    EXPECT_NE(p.error.find(reason), std::string::npos) << p.error << " / expected: " << reason;
  }
}

}  // namespace
}  // namespace swirl::view
