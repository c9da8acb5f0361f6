// The live view's wire format (swirl view; docs/view.md): what the server
// sends the page and what the page may send back, as binary WebSocket
// messages, little-endian.
//
// Frame (server → page), one per picture, only the newest state:
//   offset  0  u32  magic "SWVF"
//           4  u16  version (kFrameVersion)
//           6  u16  colour field index (into the hello's field list; 0xffff: none)
//           8  u64  step
//          16  f64  simulated time
//          24  u32  particle count n
//          28  f32  lo x, y, z   the quantisation box (the scene's box, or the
//          40  f32  hi x, y, z   frame's bounds for open space)
//          52  f32  colour min, max  (the field's range over this frame)
//          60  u16[3n]  positions, x y z per particle: lo + q/65535·(hi − lo)
//        60+6n u8[n]    colour: min + c/255·(max − min)
// 16 bits per axis resolve a 1 m box to 15 µm, below any SPH spacing swirl
// runs; 7 bytes a particle (35 000 particles: 245 kB a frame).
//
// Mesh (server → page), the fluid's surface of one state (a triangle mesh,
// render/surface_mesh.hpp), sent only to the viewers that turned the surface
// on (control 10), the newest only, like frames:
//   offset  0  u32  magic "SWVM"
//           4  u16  version (kMeshVersion)
//           6  u16  index bytes b: 2 (u16 indices; only when V ≤ 65 536) or 4 (u32)
//           8  u64  step (the state's, as in its frame; replay: the frame's index)
//          16  f64  simulated time
//          24  u32  vertex count V
//          28  u32  triangle count T
//          32  f32  lo x, y, z   the vertices' bounds: their quantisation box
//          44  f32  hi x, y, z
//          56  f32  the grid cell the mesh was made on (length)
//          60  f32  the colour field's level (iso)
//          64  u16 or u32 [3T]   vertex indices, three per triangle,
//                                counter-clockwise seen from outside
//       64+3bT u16[3V]  positions, x y z per vertex: lo + q/65535·(hi − lo)
//    64+3bT+6V i8[3V]   unit outward normals, x y z per vertex: n/127
// The indices come first so that each array starts aligned to its own type
// (the page reads the message in place). 9 bytes a vertex plus 6 or 12 a
// triangle (the dam break at 35 000 particles, cell 1 spacing: about 53 000
// vertices and 105 000 triangles, 1.1 MB). A page checks the magic, version,
// index width, length and every index (< V) before it draws a mesh.
//
// Control (page → server): one message, its first byte the kind, then a fixed
// payload (f32 little-endian); any other length, kind or a non-finite or
// out-of-range value is not a control: parse_control() says why, and the
// server drops and logs it.
//   1 pause   2 resume   3 step (one step while paused)   4 reset (start over)
//   5 speed   f32 steps per second at most (0: as fast as it runs)
//   6 colour  u8 field index
//   7 push    f32 x, y, z (a point), f32 vx, vy, vz (the drag's velocity),
//             f32 radius (> 0), f32 strength (≥ 0, 1/s), u8 on (0 or 1)
//   8 seek    u32 frame index (replay: the frame to show)
//   9 parameter  u8 which (0 viscosity, 1 gravity, 2 softening), f32 x, y, z:
//             the new value (a scalar in x with y = z = 0; gravity's g as a
//             vector). Whether the value lies in the parameter's range is the
//             session's to check (view/parameters.hpp), not the wire's.
//  10 surface u8 on (0 or 1): this viewer wants meshes (or no longer).
//             Meshes are made only while some viewer wants them.
// In a replay (`swirl view RUN_DIR`) a frame's step field holds the frame's
// index in the run's series.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "swirl/core/vec3.hpp"
#include "swirl/render/surface_mesh.hpp"

namespace swirl::view {

inline constexpr std::uint32_t kFrameMagic = 0x46565753u;  // "SWVF" read as little-endian u32
inline constexpr std::uint16_t kFrameVersion = 1;
inline constexpr std::uint16_t kNoColour = 0xffff;
inline constexpr std::size_t kFrameHeaderBytes = 60;

inline constexpr std::uint32_t kMeshMagic = 0x4D565753u;  // "SWVM" read as little-endian u32
inline constexpr std::uint16_t kMeshVersion = 1;
inline constexpr std::size_t kMeshHeaderBytes = 64;

// One picture's worth of state, gathered by the simulation thread.
struct FrameData {
  std::uint64_t step = 0;
  double time = 0;
  std::array<float, 3> lo{}, hi{};   // the quantisation box
  std::uint16_t colour_field = kNoColour;
  std::vector<float> x, y, z;        // positions
  std::vector<float> colour;         // one value per particle, or empty
};

// The message for a frame (see the header).
std::string encode_frame(const FrameData& frame);

// A frame decoded back (tests, replay tools): positions and colour as the page
// reconstructs them.
struct DecodedFrame {
  std::uint64_t step = 0;
  double time = 0;
  std::uint16_t colour_field = kNoColour;
  std::array<float, 3> lo{}, hi{};
  float colour_min = 0, colour_max = 0;
  std::vector<float> x, y, z, colour;
};
// Throws std::invalid_argument naming what is wrong with a message that is not a frame.
DecodedFrame decode_frame(std::span<const std::uint8_t> message);

// The message for the mesh of the state at `step` and `time` (see the
// header): u16 indices when it has at most 65 536 vertices. Throws
// std::invalid_argument when the mesh's arrays disagree, it has more vertices
// or triangles than a u32 counts, or a vertex is not finite.
std::string encode_mesh(const render::SurfaceMesh& mesh, std::uint64_t step, double time);

// A mesh decoded back (tests, tools), positions and normals as the page
// reconstructs them.
struct DecodedMesh {
  std::uint64_t step = 0;
  double time = 0;
  unsigned index_bytes = 4;
  std::array<float, 3> lo{}, hi{};
  float cell = 0, iso = 0;
  std::vector<Vec3<float>> vertices, normals;
  std::vector<std::uint32_t> indices;
  std::size_t triangle_count() const { return indices.size() / 3; }
};
// Throws std::invalid_argument naming what is wrong with a message that is
// not a mesh (magic, version, index width, length, bounds, an index ≥ V).
DecodedMesh decode_mesh(std::span<const std::uint8_t> message);

namespace control {
struct Pause {};
struct Resume {};
struct Step {};
struct Reset {};
struct Speed {
  float steps_per_second = 0;
};
struct Colour {
  std::uint8_t field = 0;
};
struct Push {
  Vec3<float> point, velocity;
  float radius = 0, strength = 0;
  bool on = false;
};
struct Seek {
  std::uint32_t frame = 0;
};
// The live parameters a page may change (view/parameters.hpp).
enum class ParameterId : std::uint8_t { Viscosity = 0, Gravity = 1, Softening = 2 };
inline constexpr std::uint8_t kParameterCount = 3;
struct Parameter {
  ParameterId id = ParameterId::Viscosity;
  Vec3<float> value;  // a scalar parameter's value in x (y = z = 0)
};
struct Surface {
  bool on = false;
};
}  // namespace control
using Control = std::variant<control::Pause, control::Resume, control::Step, control::Reset, control::Speed,
                             control::Colour, control::Push, control::Seek, control::Parameter, control::Surface>;

// A control message, or why it is not one (kind, length or value).
struct Parsed {
  std::optional<Control> control;
  std::string error;
};
Parsed parse_control(std::span<const std::uint8_t> message);

// The control messages as the page writes them (tests, tools).
std::string encode_control(const Control& c);

}  // namespace swirl::view
