// The names of a run's frame files, and which boundary frame goes with a
// particle frame.
//
// A run writes two series of frames (sim/run.cpp): "particles" (every particle
// that is not a boundary particle: the fluid, or the stars) and, when the scene
// has boundary particles (core/particle_kind.hpp), "boundary". A frame is
// <series>_NNNNNN.<ext> (.vtp, .h5 or .csv), NNNNNN the frame's index (six
// digits, more past 999999); each series has its own .pvd (VTK) and .xdmf
// (HDF5) listing. Boundary particles that never move are written once, with
// frame 0; moving ones with every frame. So the boundary frame in force at
// particle frame N is the boundary frame with the largest index M ≤ N.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace swirl::io {

inline constexpr std::string_view kParticleSeries = "particles";
inline constexpr std::string_view kBoundarySeries = "boundary";

// "<series>_NNNNNN<extension>", extension with its dot (".vtp").
std::string frame_file_name(std::string_view series, std::uint64_t index, std::string_view extension);

// The NNNNNN of a file named <series>_NNNNNN.<any extension>, or nullopt when
// the name is not one (at most 18 digits).
std::optional<std::uint64_t> frame_index(const std::filesystem::path& file, std::string_view series);

// The Gadget particle type to read from a frame's .h5 file: 2 (PartType2) for
// a boundary frame; nullopt (the one type the file has) for any other.
std::optional<int> frame_part_type(const std::filesystem::path& frame);

// The boundary frame in force at a particle frame particles_NNNNNN<ext>:
// boundary_MMMMMM<ext> in the same directory with the largest M ≤ N; nullopt
// when there is none or `particles_frame` is not named as a particle frame.
std::optional<std::filesystem::path> boundary_frame_for(const std::filesystem::path& particles_frame);

// Where one frame's boundary particles go when a caller writes a single frame
// (Python's write_frame): boundary_NNNNNN<ext> beside particles_NNNNNN<ext>,
// so that boundary_frame_for() pairs them as in a run; for any other name,
// <stem>_boundary<ext> beside it.
std::filesystem::path boundary_file_beside(const std::filesystem::path& frame);

}  // namespace swirl::io
