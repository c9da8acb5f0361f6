// One frame of a run as the renderer needs it: positions, time and the fields
// it can colour by, converted to double from a .vtp file (io/vtp.hpp) or an
// HDF5 snapshot (.h5, io/snapshot.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "swirl/core/vec3.hpp"

namespace swirl::render {

// What the particles are coloured by.
enum class Quantity { Speed, Density, Pressure, Mass };

Quantity parse_quantity(std::string_view name);  // "speed" | "density" | "pressure" | "mass"
std::string_view quantity_name(Quantity q);

struct Frame {
  std::filesystem::path file;
  double time = 0;                  // TimeValue, 0 when the file has none
  std::vector<Vec3d> positions;
  std::vector<Vec3d> velocity;      // each field: empty when the file has no such array
  std::vector<double> mass, density, pressure;
  std::vector<std::int32_t> kind;   // core/particle_kind.hpp (fluid 0, boundary 1); empty: all fluid
};

// Reads a .vtp or .h5 frame (by extension). A run's particle frame
// particles_NNNNNN comes with the boundary frame in force at it
// (io::boundary_frame_for), its particles appended (kind 1): the whole state
// as the run had it. Throws io::IoError naming the file for a missing,
// truncated or corrupt file, or a field of the wrong shape.
Frame load_frame(const std::filesystem::path& file);
// The particles of that one file only (a particle frame without its boundary frame).
Frame load_frame_file(const std::filesystem::path& file);

// The value of `q` per particle (speed = |velocity|). Throws io::IoError
// naming the file when the frame does not have the field.
std::vector<double> quantity_values(const Frame& frame, Quantity q);

}  // namespace swirl::render
