#include "swirl/render/fluid_surface.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"
#include "swirl/render/ply.hpp"

namespace swirl::render {

FluidSurface fluid_surface_of(const scene::Scene& scene) {
  FluidSurface s;
  if (scene.sph) s.rest_density = scene.sph->rest_density;
  s.radius = scene.surface_radius;
  s.cell = scene.surface_cell;
  s.iso = scene.surface_iso;
  return s;
}

SurfaceMesh frame_surface(const Frame& frame, const FluidSurface& settings) {
  const std::size_t n = frame.positions.size();
  if (frame.mass.size() != n)
    throw io::IoError(frame.file.string() + ": the surface needs the particles' masses, and the frame has none");
  std::vector<double> volumes(n);
  if (settings.rest_density > 0) {
    for (std::size_t i = 0; i < n; ++i) volumes[i] = frame.mass[i] / settings.rest_density;
  } else {
    if (frame.density.size() != n)
      throw io::IoError(frame.file.string() + ": the surface needs the particles' densities (or the scene's rest density)");
    for (std::size_t i = 0; i < n; ++i)
      volumes[i] = frame.density[i] > 0 ? frame.mass[i] / frame.density[i] : 0.0;
  }
  double sum = 0;
  for (double v : volumes) sum += v;
  if (n == 0 || !(sum > 0)) return SurfaceMesh{};
  const double spacing = std::cbrt(sum / static_cast<double>(n));
  return reconstruct_surface(frame.positions, volumes,
                             surface_params_for_spacing(spacing, settings.radius, settings.cell, settings.iso));
}

std::filesystem::path surface_path_for(const std::filesystem::path& frame_file) {
  std::string stem = frame_file.stem().string();
  constexpr std::string_view prefix = "particles_";
  if (stem.rfind(prefix, 0) == 0) stem = "surface_" + stem.substr(prefix.size());
  else stem = "surface_" + stem;
  return frame_file.parent_path() / (stem + ".ply");
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
    const fs::path ply = surface_path_for(drawn);
    const std::string name = ply.filename().string();
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
    write_ply(claim(ply), frame_surface(load_frame(drawn), settings), time);
    std::erase_if(*entries, [&](const SeriesEntry& e) { return e.name >= name; });
    entries->push_back({name, time});
    io::write_file_atomic(claim(run_dir / "surface.ply.series"), series_json(*entries));
  };
}

}  // namespace swirl::render
