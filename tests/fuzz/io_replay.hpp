// One input of the VTK reader fuzzer, through the real API: read_vtp() and
// read_pvd() on the same file. Each may accept it or throw IoError naming the
// file; what read_vtp() returns must be consistent with itself.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "fuzz/replay.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"

namespace swirl::fuzz {

inline std::size_t vtk_type_size(const std::string& type) {
  if (type == "Int8" || type == "UInt8") return 1;
  if (type == "Int16" || type == "UInt16") return 2;
  if (type == "Int32" || type == "UInt32" || type == "Float32") return 4;
  if (type == "Int64" || type == "UInt64" || type == "Float64") return 8;
  throw ContractViolation("read_vtp returned an array of unknown type " + type.substr(0, 40));
}

// Converts the values as a caller would, with the type the array announces.
inline std::size_t check_array(const io::VtpArray& a, std::size_t num_points, bool per_point) {
  require(a.components >= 1, "array with components < 1");
  const std::size_t size = vtk_type_size(a.type);
  const std::size_t tuple = size * static_cast<std::size_t>(a.components);
  require(a.bytes.size() % tuple == 0, "array bytes are not whole tuples");
  if (per_point) require(a.bytes.size() / tuple == num_points, "array does not have one tuple per point");
  std::size_t count = 0;
  switch (size) {
    case 1: count = a.values<std::uint8_t>().size(); break;
    case 2: count = a.values<std::uint16_t>().size(); break;
    case 4: count = a.values<float>().size(); break;
    default: count = a.values<double>().size(); break;
  }
  require(count * size == a.bytes.size(), "values() lost bytes");
  return count;
}

inline std::optional<std::string> replay_vtp(const std::filesystem::path& path) {
  try {
    const io::VtpFile f = io::read_vtp(path);
    require(f.points.components == 3, "Points without 3 components");
    require(f.points.type == "Float32" || f.points.type == "Float64", "Points not Float32/Float64");
    check_array(f.points, f.num_points, true);
    for (const auto& [name, a] : f.point_data) {
      require(!name.empty(), "PointData array without a name");
      check_array(a, f.num_points, true);
    }
    for (const auto& [name, a] : f.field_data) {
      require(!name.empty(), "FieldData array without a name");
      check_array(a, f.num_points, false);
    }
  } catch (const io::IoError& e) {
    check_error_message(e.what(), path.string());
    return std::string(e.what());
  }
  return std::nullopt;
}

inline std::optional<std::string> replay_pvd(const std::filesystem::path& path) {
  try {
    for (const io::PvdEntry& e : io::read_pvd(path)) require(!e.file.empty(), "DataSet with an empty file name");
  } catch (const io::IoError& e) {
    check_error_message(e.what(), path.string());
    return std::string(e.what());
  }
  return std::nullopt;
}

}  // namespace swirl::fuzz
