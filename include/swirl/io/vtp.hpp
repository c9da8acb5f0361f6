// VTK XML PolyData (.vtp) output, and a reader for it.
//
// One file holds one frame: the particle positions as Points, one vertex cell
// per particle (so ParaView draws them without a filter), and every output
// field of the ParticleSet (real fields as Float32/Float64, integer fields as
// Int32) plus "id" (UInt64) as PointData arrays named after the field;
// internal fields are not written. The time is a FieldData array "TimeValue". Array data are "binary appended raw": after the
// XML, an `_` and then, for each array, a UInt64 byte count and the
// little-endian values, so positions and fields are written exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "swirl/core/particle_set.hpp"

namespace swirl::io {

// Writes one frame atomically (see atomic_file.hpp).
template <class Real>
void write_vtp(const std::filesystem::path& path, const ParticleSet<Real>& particles, double time);

extern template void write_vtp<float>(const std::filesystem::path&, const ParticleSet<float>&, double);
extern template void write_vtp<double>(const std::filesystem::path&, const ParticleSet<double>&, double);

// One array read back from a .vtp file, values kept as the raw bytes written.
struct VtpArray {
  std::string type;     // VTK type name: "Float32", "Float64", "Int32", "UInt64", "Int64", ...
  int components = 1;
  std::vector<std::byte> bytes;

  // The values, converted from bytes; T must match `type` in size.
  template <class T>
  std::vector<T> values() const {
    if (bytes.size() % sizeof(T) != 0) throw std::runtime_error("VtpArray: size does not match the type");
    std::vector<T> out(bytes.size() / sizeof(T));
    if (!out.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
    return out;
  }
};

// What read_vtp found in a file.
struct VtpFile {
  std::size_t num_points = 0;
  VtpArray points;                          // components == 3, interleaved xyz
  std::map<std::string, VtpArray> point_data;
  std::map<std::string, VtpArray> field_data;  // e.g. "TimeValue"
};

// Reads a .vtp file written in the format above (appended raw, UInt64 header).
// Throws IoError naming the file and the problem for anything else.
VtpFile read_vtp(const std::filesystem::path& path);

}  // namespace swirl::io
