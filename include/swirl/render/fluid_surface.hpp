// The surface of a run's fluid, frame by frame: what `output.surface = "ply"`
// (or "obj") writes beside the frames, what `swirl render --surface` draws
// and what `swirl view` sends the page.
//
// A frame's fluid particles get the volume V_j = m_j/ρ0 (the scene's rest
// density; m_j/ρ_j when it is not known); boundary particles (a "kind" field,
// core/particle_kind.hpp) are left out: their mass is a volume weight, and
// the walls they sample are not water. The reconstruction's lengths are in
// particle spacings s = (mean V)^(1/3): kernel radius `radius`·s, grid cell
// `cell`·s, level `iso` (surface_mesh.hpp; the scene keys output.surface_radius,
// output.surface_cell and output.surface_iso, defaults 2, ½ and ½).
#pragma once

#include <filesystem>
#include <span>

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
  scene::SurfaceFormat format = scene::SurfaceFormat::Ply;  // the files surface_frames() writes
};

// A scene's surface settings (its ρ0 and output.surface* keys; the format is
// "ply" when output.surface is "none").
FluidSurface fluid_surface_of(const scene::Scene& scene);

// The surface of particles of the given volumes (one per particle), in the
// settings' spacings of their mean volume; particles of volume 0 add nothing.
// No particle, or no volume: an empty mesh. The mesh's parallel passes make
// the same mesh on any thread count (surface_mesh.hpp).
SurfaceMesh particle_surface(std::span<const Vec3d> positions, std::span<const double> volumes,
                             const FluidSurface& settings);

// The surface of one frame's fluid particles. Throws io::IoError naming the
// file when the frame lacks masses (or densities, without ρ0).
SurfaceMesh frame_surface(const Frame& frame, const FluidSurface& settings);

// The name of a frame's surface: particles_NNNNNN.vtp → surface_NNNNNN.ply
// (surface_NNNNNN.obj for the OBJ format).
std::filesystem::path surface_path_for(const std::filesystem::path& frame_file,
                                       scene::SurfaceFormat format = scene::SurfaceFormat::Ply);

// A sim::RunOptions::on_frame hook for output.surface = "ply" or "obj": reads
// each frame just written (.vtp or .h5) and writes its surface as
// run_dir/surface_NNNNNN.ply (.obj), claimed in the run's manifest first (a
// file the run did not make is never overwritten) and written atomically.
// PLY also gets the series run_dir/surface.ply.series (a ParaView file
// series: names and times; on resume it starts from the surfaces already
// there). OBJ gets none: ParaView's OBJ reader takes one file, not a series
// (docs/surface.md says what to open); each OBJ has its time in a comment.
sim::FrameHook surface_frames(std::filesystem::path run_dir, FluidSurface settings);

}  // namespace swirl::render
