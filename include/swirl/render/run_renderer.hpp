// Rendering the frames of a run directory (what `swirl render` and `swirl run
// --render-every` use).
//
// A run directory holds particles.pvd, particles_NNNNNN.vtp and scene.toml
// (the effective scene). RunRenderer fixes, once, everything that must not
// change between the frames of one movie, so the movie does not flicker:
//   camera  — fitted to the scene's box when it has walls, else to the first
//             frame's particles (the 0.5 %–99.5 % range per axis, so a few
//             escapers do not shrink the picture);
//   colours — --range when given, else the first frame's values (0.5 %–99.5 %);
//             when those are all equal (speed at rest), a scale from the scene:
//             free-fall speed √(2|g|H) across the box height H, hydrostatic
//             pressure ρ0|g|H, ±3 % of the rest density;
//   gravity runs coloured by density show log10 of the surface density Σ,
//             over four decades below the first frame's peak;
//   --surface: the fluid's surface mesh (fluid_surface.hpp) drawn as water
//             (water.hpp) instead of splats, without a colour bar.
// Each picture: splats (or Σ), the box's edges, the time in the top-left
// corner and a colour bar with its units on the right.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "swirl/core/box.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/render/camera.hpp"
#include "swirl/render/fluid_surface.hpp"
#include "swirl/render/font.hpp"
#include "swirl/render/frame.hpp"
#include "swirl/render/image.hpp"
#include "swirl/sim/run.hpp"

namespace swirl::render {

struct RenderOptions {
  View view = View::Front;
  std::optional<Projection> projection;          // default: perspective for iso, else orthographic
  std::optional<Quantity> color;                 // default: density for gravity runs, else speed
  int width = 1280, height = 720;                // pixels, each ≥ 64
  std::optional<std::pair<double, double>> range;  // colour range (log10 Σ for the gravity density view)
  bool surface = false;                          // the fluid as a water surface (fluid_surface.hpp, water.hpp)
};

// What a run directory says about itself.
struct RunInfo {
  std::filesystem::path dir;
  std::vector<io::PvdEntry> frames;   // from particles.pvd (or the .vtp files when it is missing)
  bool has_scene = false;             // scene.toml was found and read
  bool nbody = false;                 // a gravity run (G = 1 units)
  std::optional<Box<double>> box;     // the walls, when the scene has them
  Vec3d gravity{};                    // uniform gravity, m/s²
  double rest_density = 0;            // SPH ρ0, kg/m³ (0: not a fluid)
  std::string scene_name;             // the scene file's stem, for captions
  FluidSurface surface;               // the surface's settings (ρ0 and the scene's output.surface_* keys)
};

// Reads particles.pvd (or lists particles_*.vtp) and scene.toml. Throws
// io::IoError naming the directory when it holds no frames, or a file that
// cannot be read.
RunInfo read_run(const std::filesystem::path& dir);

// What a scene says for its pictures (read_run's part from scene.toml), for a
// run that has no folder (a Simulation drawn from Python): no frames.
RunInfo run_info_of(const scene::Scene& scene);

// The PNG a frame is rendered to: out_dir / (the frame's stem + ".png").
std::filesystem::path png_path_for(const std::filesystem::path& out_dir, const std::filesystem::path& frame_file);

class RunRenderer {
 public:
  // Loads the font and the run's first frame to fix the camera and colours.
  RunRenderer(RunInfo run, RenderOptions options);
  // The same, the camera and colours fixed from `first` instead of a file.
  RunRenderer(const Frame& first, RunInfo run, RenderOptions options);

  // The picture of one frame. Parallel inside (bit-identical for any thread
  // count), but not to be called from two threads at once (one Font).
  Image render(const Frame& frame) const;

  // Reads `frame_file`, renders it and writes `png` atomically (a failure
  // leaves no PNG). Throws io::IoError.
  void render_file(const std::filesystem::path& frame_file, const std::filesystem::path& png) const;

  const Camera& camera() const { return camera_; }
  std::pair<double, double> range() const { return range_; }
  Quantity quantity() const { return quantity_; }
  bool log_density_view() const { return log_density_; }
  const RunInfo& run() const { return run_; }

 private:
  RunInfo run_;
  RenderOptions options_;
  Font font_;
  Quantity quantity_ = Quantity::Speed;
  bool log_density_ = false;
  Camera camera_;
  Box<double> bounds_;
  std::pair<double, double> range_{0, 1};
  double splat_radius_ = 0.01;
  int plot_width_ = 0;  // pixels left of the colour bar
};

// A sim::RunOptions::on_frame hook for `swirl run --render-every K`: renders
// every frame whose number (particles_NNNNNN) is a multiple of `every` to
// run_dir/render/particles_NNNNNN.png. The RunRenderer is set up at the first
// call, from the run's frame 0 (already on disk then, also on resume), so the
// pictures match `swirl render --all`. It only reads frames, so the run's
// results do not change; a failure throws io::IoError, which stops the run
// like a failed frame write. Each picture is claimed in the run's manifest
// before it is drawn: a picture the run did not make is never overwritten,
// and --overwrite deletes the run's pictures with its frames.
sim::FrameHook render_every(std::filesystem::path run_dir, std::uint64_t every, RenderOptions options = {});

}  // namespace swirl::render
