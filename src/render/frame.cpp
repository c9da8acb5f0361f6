#include "swirl/render/frame.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "swirl/core/particle_kind.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/frame_names.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/vtp.hpp"

namespace swirl::render {
namespace {

// The values of a Float32/Float64 array as doubles; components must match.
std::vector<double> as_doubles(const std::filesystem::path& file, const std::string& name, const io::VtpArray& a,
                               int components, std::size_t points) {
  if (a.components != components)
    throw io::IoError(file.string() + ": array '" + name + "' has " + std::to_string(a.components) +
                      " components, expected " + std::to_string(components));
  std::vector<double> out;
  if (a.type == "Float64") {
    out = a.values<double>();
  } else if (a.type == "Float32") {
    const auto f = a.values<float>();
    out.assign(f.begin(), f.end());
  } else {
    throw io::IoError(file.string() + ": array '" + name + "' is " + a.type + ", expected Float32 or Float64");
  }
  if (out.size() != points * static_cast<std::size_t>(components))
    throw io::IoError(file.string() + ": array '" + name + "' has " + std::to_string(out.size()) +
                      " values for " + std::to_string(points) + " points");
  return out;
}

std::vector<Vec3d> as_vectors(const std::vector<double>& xyz) {
  std::vector<Vec3d> v(xyz.size() / 3);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
  return v;
}

}  // namespace

Quantity parse_quantity(std::string_view name) {
  if (name == "speed") return Quantity::Speed;
  if (name == "density") return Quantity::Density;
  if (name == "pressure") return Quantity::Pressure;
  if (name == "mass") return Quantity::Mass;
  throw std::invalid_argument("unknown colour quantity '" + std::string(name) + "' (speed, density, pressure or mass)");
}

std::string_view quantity_name(Quantity q) {
  switch (q) {
    case Quantity::Speed: return "speed";
    case Quantity::Density: return "density";
    case Quantity::Pressure: return "pressure";
    case Quantity::Mass: return "mass";
  }
  return "?";
}

namespace {
// An HDF5 snapshot as a frame: its Gadget datasets by their names.
Frame load_snapshot_frame(const std::filesystem::path& file) {
  const io::SnapshotFile s = io::read_snapshot(file, io::frame_part_type(file));  // checks shapes and finiteness
  Frame f;
  f.file = file;
  f.time = s.info.time;
  f.positions = as_vectors(s.datasets.at("Coordinates").values);
  f.velocity = as_vectors(s.datasets.at("Velocities").values);
  f.mass = s.datasets.at("Masses").values;
  const auto scalar = [&](const char* name, std::vector<double>& out) {
    if (const auto it = s.datasets.find(name); it != s.datasets.end() && it->second.columns == 1) out = it->second.values;
  };
  scalar("Density", f.density);
  scalar("Pressure", f.pressure);
  if (const auto it = s.datasets.find(std::string(kKindField)); it != s.datasets.end() && it->second.columns == 1)
    for (const double k : it->second.values) f.kind.push_back(static_cast<std::int32_t>(k));
  return f;
}

}  // namespace

Frame load_frame_file(const std::filesystem::path& file) {
  if (file.extension() == ".h5") return load_snapshot_frame(file);
  const io::VtpFile vtp = io::read_vtp(file);
  Frame f;
  f.file = file;
  const std::size_t n = vtp.num_points;
  f.positions = as_vectors(as_doubles(file, "Points", vtp.points, 3, n));
  if (auto it = vtp.field_data.find("TimeValue"); it != vtp.field_data.end()) {
    const auto t = as_doubles(file, "TimeValue", it->second, 1, it->second.bytes.empty() ? 0 : 1);
    if (!t.empty()) f.time = t.front();
  }
  auto scalar = [&](const char* name, std::vector<double>& out) {
    if (auto it = vtp.point_data.find(name); it != vtp.point_data.end()) out = as_doubles(file, name, it->second, 1, n);
  };
  if (auto it = vtp.point_data.find("velocity"); it != vtp.point_data.end())
    f.velocity = as_vectors(as_doubles(file, "velocity", it->second, 3, n));
  scalar("mass", f.mass);
  scalar("density", f.density);
  scalar("pressure", f.pressure);
  if (auto it = vtp.point_data.find(std::string(kKindField)); it != vtp.point_data.end()) {
    if (it->second.type != "Int32" || it->second.components != 1)
      throw io::IoError(file.string() + ": array 'kind' is " + it->second.type + ", expected Int32");
    f.kind = it->second.values<std::int32_t>();
    if (f.kind.size() != n)
      throw io::IoError(file.string() + ": array 'kind' has " + std::to_string(f.kind.size()) + " values for " +
                        std::to_string(n) + " points");
  }
  for (const Vec3d& p : f.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw io::IoError(file.string() + ": a particle position is not finite");
  return f;
}

namespace {

// Appends `more`'s particles to `to`: a field either frame lacks is dropped,
// and a frame without kinds is all fluid.
void append(Frame& to, Frame more) {
  const std::size_t n = to.positions.size(), m = more.positions.size();
  if (to.kind.empty()) to.kind.assign(n, std::int32_t(ParticleKind::Fluid));
  if (more.kind.empty()) more.kind.assign(m, std::int32_t(ParticleKind::Fluid));
  const auto join = [&](auto& a, auto& b) {
    if (a.size() == n && b.size() == m) a.insert(a.end(), b.begin(), b.end());
    else a.clear();
  };
  join(to.velocity, more.velocity);
  join(to.mass, more.mass);
  join(to.density, more.density);
  join(to.pressure, more.pressure);
  join(to.kind, more.kind);
  to.positions.insert(to.positions.end(), more.positions.begin(), more.positions.end());
}

}  // namespace

Frame load_frame(const std::filesystem::path& file) {
  Frame f = load_frame_file(file);
  if (const auto walls = io::boundary_frame_for(file)) append(f, load_frame_file(*walls));
  return f;
}

std::vector<double> quantity_values(const Frame& frame, Quantity q) {
  const std::size_t n = frame.positions.size();
  auto missing = [&](const char* field) {
    return io::IoError(frame.file.string() + ": no point array '" + field + "' to colour by " +
                       std::string(quantity_name(q)));
  };
  switch (q) {
    case Quantity::Speed: {
      if (frame.velocity.size() != n) throw missing("velocity");
      std::vector<double> s(n);
      for (std::size_t i = 0; i < n; ++i) s[i] = norm(frame.velocity[i]);
      return s;
    }
    case Quantity::Density:
      if (frame.density.size() != n) throw missing("density");
      return frame.density;
    case Quantity::Pressure:
      if (frame.pressure.size() != n) throw missing("pressure");
      return frame.pressure;
    case Quantity::Mass:
      if (frame.mass.size() != n) throw missing("mass");
      return frame.mass;
  }
  throw missing("?");
}

}  // namespace swirl::render
