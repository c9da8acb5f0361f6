#include "swirl/view/wire.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace swirl::view {
namespace {

static_assert(std::endian::native == std::endian::little, "the wire format is little-endian, as is every host swirl runs on");

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

template <class T>
T get(std::span<const std::uint8_t> in, std::size_t offset) {
  T value;
  std::memcpy(&value, in.data() + offset, sizeof(T));
  return value;
}

// q in [0, levels] for v in [lo, hi] (clamped: a particle outside the box is drawn on its face).
std::uint32_t quantise(float v, float lo, float scale, std::uint32_t levels) {
  const float q = std::round((v - lo) * scale);
  if (!(q > 0)) return 0;  // also NaN
  return q >= float(levels) ? levels : std::uint32_t(q);
}

}  // namespace

std::string encode_frame(const FrameData& f) {
  const std::size_t n = f.x.size();
  if (f.y.size() != n || f.z.size() != n || (!f.colour.empty() && f.colour.size() != n))
    throw std::invalid_argument("encode_frame: the arrays differ in length");
  float cmin = 0, cmax = 0;
  if (!f.colour.empty()) {
    cmin = INFINITY, cmax = -INFINITY;
    for (const float c : f.colour)
      if (std::isfinite(c)) cmin = std::min(cmin, c), cmax = std::max(cmax, c);
    if (!(cmin <= cmax)) cmin = cmax = 0;  // no finite value
  }
  std::string out;
  out.reserve(kFrameHeaderBytes + 7 * n);
  put(out, kFrameMagic);
  put(out, kFrameVersion);
  put(out, f.colour.empty() ? kNoColour : f.colour_field);
  put(out, f.step);
  put(out, f.time);
  put(out, std::uint32_t(n));
  for (const float v : f.lo) put(out, v);
  for (const float v : f.hi) put(out, v);
  put(out, cmin);
  put(out, cmax);
  const std::array<const std::vector<float>*, 3> axes{&f.x, &f.y, &f.z};
  std::array<float, 3> scale{};
  for (int a = 0; a < 3; ++a) {
    const float extent = f.hi[std::size_t(a)] - f.lo[std::size_t(a)];
    scale[std::size_t(a)] = extent > 0 ? 65535.0f / extent : 0.0f;
  }
  const std::size_t positions = out.size();
  out.resize(positions + 6 * n + n);
  auto* p = reinterpret_cast<unsigned char*>(out.data() + positions);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t a = 0; a < 3; ++a) {
      const auto q = std::uint16_t(quantise((*axes[a])[i], f.lo[a], scale[a], 65535));
      std::memcpy(p + 6 * i + 2 * a, &q, 2);
    }
  unsigned char* c = p + 6 * n;
  const float cscale = cmax > cmin ? 255.0f / (cmax - cmin) : 0.0f;
  for (std::size_t i = 0; i < n && !f.colour.empty(); ++i) c[i] = std::uint8_t(quantise(f.colour[i], cmin, cscale, 255));
  if (f.colour.empty()) std::fill(c, c + n, std::uint8_t(0));
  return out;
}

DecodedFrame decode_frame(std::span<const std::uint8_t> m) {
  if (m.size() < kFrameHeaderBytes) throw std::invalid_argument(fmt::format("frame: {} bytes, shorter than the header", m.size()));
  if (get<std::uint32_t>(m, 0) != kFrameMagic) throw std::invalid_argument("frame: not a swirl frame (magic)");
  if (const auto v = get<std::uint16_t>(m, 4); v != kFrameVersion)
    throw std::invalid_argument(fmt::format("frame: version {}, this reader knows {}", v, kFrameVersion));
  DecodedFrame f;
  f.colour_field = get<std::uint16_t>(m, 6);
  f.step = get<std::uint64_t>(m, 8);
  f.time = get<double>(m, 16);
  const std::size_t n = get<std::uint32_t>(m, 24);
  for (std::size_t a = 0; a < 3; ++a) {
    f.lo[a] = get<float>(m, 28 + 4 * a);
    f.hi[a] = get<float>(m, 40 + 4 * a);
  }
  f.colour_min = get<float>(m, 52);
  f.colour_max = get<float>(m, 56);
  if (m.size() != kFrameHeaderBytes + 7 * n)
    throw std::invalid_argument(fmt::format("frame: {} bytes for {} particles, expected {}", m.size(), n, kFrameHeaderBytes + 7 * n));
  f.x.resize(n), f.y.resize(n), f.z.resize(n), f.colour.resize(n);
  std::array<std::vector<float>*, 3> axes{&f.x, &f.y, &f.z};
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      const auto q = get<std::uint16_t>(m, kFrameHeaderBytes + 6 * i + 2 * a);
      (*axes[a])[i] = f.lo[a] + float(q) / 65535.0f * (f.hi[a] - f.lo[a]);
    }
    f.colour[i] = f.colour_min + float(m[kFrameHeaderBytes + 6 * n + i]) / 255.0f * (f.colour_max - f.colour_min);
  }
  return f;
}

std::string encode_mesh(const render::SurfaceMesh& mesh, std::uint64_t step, double time) {
  const std::size_t v = mesh.vertices.size(), t = mesh.triangle_count();
  if (mesh.normals.size() != v || mesh.indices.size() != 3 * t)
    throw std::invalid_argument("encode_mesh: the mesh's arrays differ in length");
  if (v > 0xffffffffu || t > 0xffffffffu) throw std::invalid_argument("encode_mesh: more than 2^32 vertices or triangles");
  std::array<float, 3> lo{}, hi{};
  if (v > 0) lo = hi = {mesh.vertices[0].x, mesh.vertices[0].y, mesh.vertices[0].z};
  for (const auto& p : mesh.vertices)
    for (std::size_t a = 0; a < 3; ++a) {
      if (!std::isfinite(p[int(a)])) throw std::invalid_argument("encode_mesh: a vertex is not finite");
      lo[a] = std::min(lo[a], p[int(a)]), hi[a] = std::max(hi[a], p[int(a)]);
    }
  const std::uint16_t index_bytes = v <= 65536 ? 2 : 4;
  std::string out;
  out.reserve(kMeshHeaderBytes + 3 * index_bytes * t + 9 * v);
  put(out, kMeshMagic);
  put(out, kMeshVersion);
  put(out, index_bytes);
  put(out, step);
  put(out, time);
  put(out, std::uint32_t(v));
  put(out, std::uint32_t(t));
  for (const float x : lo) put(out, x);
  for (const float x : hi) put(out, x);
  put(out, float(mesh.cell_size));
  put(out, float(mesh.iso));
  for (const std::uint32_t i : mesh.indices) {
    if (i >= v) throw std::invalid_argument(fmt::format("encode_mesh: index {} of {} vertices", i, v));
    if (index_bytes == 2) put(out, std::uint16_t(i));
    else put(out, i);
  }
  std::array<float, 3> scale{};
  for (std::size_t a = 0; a < 3; ++a) scale[a] = hi[a] > lo[a] ? 65535.0f / (hi[a] - lo[a]) : 0.0f;
  for (const auto& p : mesh.vertices)
    for (std::size_t a = 0; a < 3; ++a) put(out, std::uint16_t(quantise(p[int(a)], lo[a], scale[a], 65535)));
  for (const auto& n : mesh.normals)
    for (int a = 0; a < 3; ++a) {
      const float q = std::round(std::clamp(n[a], -1.0f, 1.0f) * 127.0f);  // NaN: 0 (no direction)
      out.push_back(static_cast<char>(std::isfinite(q) ? std::int8_t(q) : std::int8_t{0}));
    }
  return out;
}

DecodedMesh decode_mesh(std::span<const std::uint8_t> m) {
  if (m.size() < kMeshHeaderBytes) throw std::invalid_argument(fmt::format("mesh: {} bytes, shorter than the header", m.size()));
  if (get<std::uint32_t>(m, 0) != kMeshMagic) throw std::invalid_argument("mesh: not a swirl mesh (magic)");
  if (const auto v = get<std::uint16_t>(m, 4); v != kMeshVersion)
    throw std::invalid_argument(fmt::format("mesh: version {}, this reader knows {}", v, kMeshVersion));
  DecodedMesh d;
  d.index_bytes = get<std::uint16_t>(m, 6);
  d.step = get<std::uint64_t>(m, 8);
  d.time = get<double>(m, 16);
  const std::uint64_t v = get<std::uint32_t>(m, 24), t = get<std::uint32_t>(m, 28);
  for (std::size_t a = 0; a < 3; ++a) {
    d.lo[a] = get<float>(m, 32 + 4 * a);
    d.hi[a] = get<float>(m, 44 + 4 * a);
    if (!std::isfinite(d.lo[a]) || !std::isfinite(d.hi[a]) || d.lo[a] > d.hi[a])
      throw std::invalid_argument("mesh: its bounds are not finite, or lo > hi");
  }
  d.cell = get<float>(m, 56);
  d.iso = get<float>(m, 60);
  if (d.index_bytes != 2 && d.index_bytes != 4)
    throw std::invalid_argument(fmt::format("mesh: {}-byte indices (2 or 4)", d.index_bytes));
  if (d.index_bytes == 2 && v > 65536)
    throw std::invalid_argument(fmt::format("mesh: 2-byte indices for {} vertices", v));
  const std::uint64_t expected = kMeshHeaderBytes + 3 * d.index_bytes * t + 9 * v;
  if (m.size() != expected)
    throw std::invalid_argument(
        fmt::format("mesh: {} bytes for {} vertices and {} triangles, expected {}", m.size(), v, t, expected));
  d.indices.resize(3 * t);
  for (std::size_t k = 0; k < 3 * t; ++k) {
    const std::size_t at = kMeshHeaderBytes + d.index_bytes * k;
    const std::uint32_t i = d.index_bytes == 2 ? get<std::uint16_t>(m, at) : get<std::uint32_t>(m, at);
    if (i >= v) throw std::invalid_argument(fmt::format("mesh: triangle {} names vertex {} of {}", k / 3, i, v));
    d.indices[k] = i;
  }
  const std::size_t positions = kMeshHeaderBytes + 3 * d.index_bytes * t, normals = positions + 6 * v;
  d.vertices.resize(v);
  d.normals.resize(v);
  for (std::size_t i = 0; i < v; ++i)
    for (std::size_t a = 0; a < 3; ++a) {
      const auto q = get<std::uint16_t>(m, positions + 6 * i + 2 * a);
      d.vertices[i][int(a)] = d.lo[a] + float(q) / 65535.0f * (d.hi[a] - d.lo[a]);
      d.normals[i][int(a)] = float(static_cast<std::int8_t>(m[normals + 3 * i + a])) / 127.0f;
    }
  return d;
}

namespace {
enum Kind : std::uint8_t {
  kPause = 1, kResume = 2, kStep = 3, kReset = 4, kSpeed = 5, kColour = 6, kPush = 7, kSeek = 8, kParameter = 9,
  kSurface = 10
};
constexpr std::size_t kPayload[] = {0, 0, 0, 0, 0, 4, 1, 33, 4, 13, 1};  // bytes after the kind, by kind

Parsed refuse(std::string why) { return Parsed{std::nullopt, std::move(why)}; }
}  // namespace

Parsed parse_control(std::span<const std::uint8_t> m) {
  if (m.empty()) return refuse("an empty message");
  const std::uint8_t kind = m[0];
  if (kind < kPause || kind > kSurface) return refuse(fmt::format("unknown control kind {}", kind));
  if (m.size() != 1 + kPayload[kind])
    return refuse(fmt::format("control kind {} has {} bytes, expected {}", kind, m.size(), 1 + kPayload[kind]));
  auto f32 = [&](std::size_t k) { return get<float>(m, 1 + 4 * k); };
  switch (kind) {
    case kPause: return {control::Pause{}, {}};
    case kResume: return {control::Resume{}, {}};
    case kStep: return {control::Step{}, {}};
    case kReset: return {control::Reset{}, {}};
    case kSpeed: {
      const float s = f32(0);
      if (!std::isfinite(s) || s < 0) return refuse(fmt::format("speed {}: must be finite and >= 0", s));
      return {control::Speed{s}, {}};
    }
    case kColour: return {control::Colour{m[1]}, {}};
    case kSeek: return {control::Seek{get<std::uint32_t>(m, 1)}, {}};
    case kSurface:
      if (m[1] > 1) return refuse("surface: 'on' must be 0 or 1");
      return {control::Surface{m[1] == 1}, {}};
    case kParameter: {
      if (m[1] >= control::kParameterCount) return refuse(fmt::format("parameter: unknown parameter {}", m[1]));
      const auto v = [&](std::size_t k) { return get<float>(m, 2 + 4 * k); };
      for (std::size_t k = 0; k < 3; ++k)
        if (!std::isfinite(v(k))) return refuse("parameter: a value is not finite");
      const auto id = static_cast<control::ParameterId>(m[1]);
      if (id != control::ParameterId::Gravity && (v(1) != 0 || v(2) != 0))
        return refuse("parameter: a scalar parameter's y and z must be 0");
      return {control::Parameter{id, {v(0), v(1), v(2)}}, {}};
    }
    default: {
      control::Push p;
      for (int k = 0; k < 8; ++k)
        if (!std::isfinite(f32(std::size_t(k)))) return refuse("push: a value is not finite");
      p.point = {f32(0), f32(1), f32(2)};
      p.velocity = {f32(3), f32(4), f32(5)};
      p.radius = f32(6);
      p.strength = f32(7);
      if (!(p.radius > 0) || p.strength < 0) return refuse("push: radius must be > 0 and strength >= 0");
      if (m[33] > 1) return refuse("push: 'on' must be 0 or 1");
      p.on = m[33] == 1;
      return {p, {}};
    }
  }
}

std::string encode_control(const Control& c) {
  std::string out;
  std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, control::Pause>) out.push_back(char(kPause));
        else if constexpr (std::is_same_v<T, control::Resume>) out.push_back(char(kResume));
        else if constexpr (std::is_same_v<T, control::Step>) out.push_back(char(kStep));
        else if constexpr (std::is_same_v<T, control::Reset>) out.push_back(char(kReset));
        else if constexpr (std::is_same_v<T, control::Speed>) {
          out.push_back(char(kSpeed));
          put(out, v.steps_per_second);
        } else if constexpr (std::is_same_v<T, control::Colour>) {
          out.push_back(char(kColour));
          out.push_back(char(v.field));
        } else if constexpr (std::is_same_v<T, control::Seek>) {
          out.push_back(char(kSeek));
          put(out, v.frame);
        } else if constexpr (std::is_same_v<T, control::Surface>) {
          out.push_back(char(kSurface));
          out.push_back(char(v.on ? 1 : 0));
        } else if constexpr (std::is_same_v<T, control::Parameter>) {
          out.push_back(char(kParameter));
          out.push_back(char(v.id));
          for (const float x : {v.value.x, v.value.y, v.value.z}) put(out, x);
        } else {
          out.push_back(char(kPush));
          for (const float x : {v.point.x, v.point.y, v.point.z, v.velocity.x, v.velocity.y, v.velocity.z, v.radius, v.strength})
            put(out, x);
          out.push_back(char(v.on ? 1 : 0));
        }
      },
      c);
  return out;
}

}  // namespace swirl::view
