// The surface of a run's fluid, frame by frame: what `output.surface = "ply"`
// writes beside the frames and what `swirl render --surface` draws.
//
// A frame's particles get the volume V_j = m_j/ρ0 (the scene's rest density;
// m_j/ρ_j when it is not known) and the reconstruction's lengths are in
// particle spacings s = (mean V)^(1/3): kernel radius `radius`·s, grid cell
// `cell`·s, level `iso` (surface_mesh.hpp; the scene keys output.surface_radius,
// output.surface_cell and output.surface_iso, defaults 2, ½ and ½).
#pragma once

#include <filesystem>

#include "swirl/render/frame.hpp"
#include "swirl/render/surface_mesh.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/sim/run.hpp"

namespace swirl::render {

struct FluidSurface {
  double rest_density = 0;  // ρ0, kg/m³; 0: use each particle's density
  double radius = 2.0;      // kernel radius, particle spacings
  double cell = 0.5;        // grid cell, particle spacings
  double iso = 0.5;         // level of the colour field
};

// A scene's surface settings (its ρ0 and output.surface_* keys).
FluidSurface fluid_surface_of(const scene::Scene& scene);

// The surface of one frame. Throws io::IoError naming the file when the
// frame lacks masses (or densities, without ρ0).
SurfaceMesh frame_surface(const Frame& frame, const FluidSurface& settings);

// The name of a frame's surface: particles_NNNNNN.vtp → surface_NNNNNN.ply.
std::filesystem::path surface_path_for(const std::filesystem::path& frame_file);

// A sim::RunOptions::on_frame hook for output.surface = "ply": reads each
// frame just written (.vtp or .h5), writes its surface as
// run_dir/surface_NNNNNN.ply and the series run_dir/surface.ply.series (a
// ParaView file series: names and times), each claimed in the run's manifest
// first (a file the run did not make is never overwritten) and written
// atomically. On resume the series starts from the surfaces already there.
sim::FrameHook surface_frames(std::filesystem::path run_dir, FluidSurface settings);

}  // namespace swirl::render
