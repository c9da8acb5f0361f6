#include "swirl/render/fluid_surface.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/render/obj.hpp"
#include "swirl/render/ply.hpp"

namespace swirl::render {

FluidSurface fluid_surface_of(const scene::Scene& scene) {
  FluidSurface s;
  if (scene.sph) s.rest_density = scene.sph->rest_density;
  s.radius = scene.surface_radius;
  s.cell = scene.surface_cell;
  s.iso = scene.surface_iso;
  if (scene.surface != scene::SurfaceFormat::None) s.format = scene.surface;
  return s;
}

SurfaceMesh particle_surface(std::span<const Vec3d> positions, std::span<const double> volumes,
                             const FluidSurface& settings) {
  if (volumes.size() != positions.size())
    throw std::invalid_argument("surface: one volume per particle");
  const std::size_t n = positions.size();
  double sum = 0;
  for (double v : volumes) sum += v;
  if (n == 0 || !(sum > 0)) return SurfaceMesh{};
  const double spacing = std::cbrt(sum / static_cast<double>(n));
  return reconstruct_surface(positions, volumes,
                             surface_params_for_spacing(spacing, settings.radius, settings.cell, settings.iso));
}

SurfaceMesh frame_surface(const Frame& frame, const FluidSurface& settings) {
  const std::size_t n = frame.positions.size();
  if (frame.mass.size() != n)
    throw io::IoError(frame.file.string() + ": the surface needs the particles' masses, and the frame has none");
  if (settings.rest_density <= 0 && frame.density.size() != n)
    throw io::IoError(frame.file.string() + ": the surface needs the particles' densities (or the scene's rest density)");
  std::vector<Vec3d> positions;
  std::vector<double> volumes;
  positions.reserve(n);
  volumes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!frame.kind.empty() && is_boundary(frame.kind[i])) continue;
    positions.push_back(frame.positions[i]);
    if (settings.rest_density > 0) volumes.push_back(frame.mass[i] / settings.rest_density);
    else volumes.push_back(frame.density[i] > 0 ? frame.mass[i] / frame.density[i] : 0.0);
  }
  return particle_surface(positions, volumes, settings);
}

std::filesystem::path surface_path_for(const std::filesystem::path& frame_file, scene::SurfaceFormat format) {
  std::string stem = frame_file.stem().string();
  constexpr std::string_view prefix = "particles_";
  if (stem.rfind(prefix, 0) == 0) stem = "surface_" + stem.substr(prefix.size());
  else stem = "surface_" + stem;
  return frame_file.parent_path() / (stem + (format == scene::SurfaceFormat::Obj ? ".obj" : ".ply"));
}

namespace {

struct SeriesEntry {
  std::string name;
  double time = 0;
};

std::string series_json(const std::vector<SeriesEntry>& entries) {
  std::string out = "{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n";
  for (std::size_t i = 0; i < entries.size(); ++i)
    out += fmt::format("    {{ \"name\" : \"{}\", \"time\" : {:.17g} }}{}\n", entries[i].name, entries[i].time,
                       i + 1 < entries.size() ? "," : "");
  out += "  ]\n}\n";
  return out;
}

}  // namespace

sim::FrameHook surface_frames(std::filesystem::path run_dir, FluidSurface settings) {
  auto entries = std::make_shared<std::vector<SeriesEntry>>();
  auto started = std::make_shared<bool>(false);
  return [run_dir = std::move(run_dir), settings, entries, started](const std::filesystem::path& frame, double time,
                                                                     const sim::ClaimFile& claim) {
    namespace fs = std::filesystem;
    fs::path drawn = frame;
    for (const char* extension : {".vtp", ".h5"}) {
      drawn.replace_extension(extension);
      if (fs::exists(drawn)) break;
    }
    if (!fs::exists(drawn))
      throw io::IoError(frame.string() + ": output.surface needs .vtp or .h5 frames (output.format must include "
                        "\"vtp\" or \"hdf5\")");
    const fs::path file = surface_path_for(drawn, settings.format);
    if (settings.format == scene::SurfaceFormat::Obj) {
      write_obj(claim(file), frame_surface(load_frame_file(drawn), settings), time);
      return;
    }
    const std::string name = file.filename().string();
    if (!*started) {
      // A resumed run: the surfaces of the frames before this one, from their headers.
      *started = true;
      std::vector<std::string> names;
      if (fs::is_directory(run_dir))
        for (const auto& e : fs::directory_iterator(run_dir)) {
          const std::string other = e.path().filename().string();
          if (e.is_regular_file() && other.rfind("surface_", 0) == 0 && e.path().extension() == ".ply" && other < name)
            names.push_back(other);
        }
      std::sort(names.begin(), names.end());
      for (auto& other : names) entries->push_back({other, read_ply(run_dir / other).time});
    }
    write_ply(claim(file), frame_surface(load_frame_file(drawn), settings), time);
    std::erase_if(*entries, [&](const SeriesEntry& e) { return e.name >= name; });
    entries->push_back({name, time});
    io::write_file_atomic(claim(run_dir / "surface.ply.series"), series_json(*entries));
  };
}

}  // namespace swirl::render
