#include "swirl/render/run_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/frame_names.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/render/png.hpp"
#include "swirl/render/splats.hpp"
#include "swirl/render/surface_density.hpp"
#include "swirl/render/water.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::render {
namespace {

constexpr Color kBackground{0.13f, 0.13f, 0.15f};
constexpr Color kText{0.92f, 0.92f, 0.92f};
constexpr Color kEdge{0.45f, 0.45f, 0.5f};
constexpr double kLowQuantile = 0.005, kHighQuantile = 0.995;
constexpr double kLogDecades = 4.0;  // dynamic range of the log-density view

// The q-quantile of values (nearest rank; values is copied).
double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

// The fluid's particles of a frame (all of them in a frame without kinds):
// what the colour range and the splats' size are taken from, so that the
// boundary particles' volume weights and pressures do not set them.
Frame fluid_part(const Frame& f) {
  if (f.kind.empty()) return f;
  Frame out;
  out.file = f.file, out.time = f.time;
  const auto keep = [&f](const auto& from, auto& to) {
    if (from.size() != f.kind.size()) return;  // a field the file does not have
    for (std::size_t i = 0; i < from.size(); ++i)
      if (!is_boundary(f.kind[i])) to.push_back(from[i]);
  };
  keep(f.positions, out.positions), keep(f.velocity, out.velocity), keep(f.mass, out.mass);
  keep(f.density, out.density), keep(f.pressure, out.pressure);
  return out;
}

// True strictly inside the box: the box walls' boundary particles lie a layer
// outside its faces (scene::wall_offset), an obstacle's inside.
bool strictly_inside(const Box<double>& box, const Vec3d& p) {
  return p.x > box.lo.x && p.x < box.hi.x && p.y > box.lo.y && p.y < box.hi.y && p.z > box.lo.z && p.z < box.hi.z;
}

// Bounds of most particles (0.5 %–99.5 % per axis), padded by 10 %.
Box<double> robust_bounds(const std::vector<Vec3d>& positions) {
  Box<double> b;
  double largest = 0;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> c(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) c[i] = positions[i][axis];
    b.lo[axis] = quantile(c, kLowQuantile);
    b.hi[axis] = quantile(c, kHighQuantile);
    largest = std::max(largest, b.hi[axis] - b.lo[axis]);
  }
  if (!(largest > 0)) largest = 1;  // one particle, or all at one point
  for (int axis = 0; axis < 3; ++axis) {
    const double pad = std::max(0.1 * (b.hi[axis] - b.lo[axis]), 0.05 * largest);
    b.lo[axis] -= pad;
    b.hi[axis] += pad;
  }
  return b;
}

std::string quantity_title(Quantity q, bool nbody, bool log_density) {
  if (log_density) return "surface density";
  const char* name = q == Quantity::Speed ? "speed" : q == Quantity::Density ? "density" : q == Quantity::Pressure ? "pressure" : "mass";
  if (nbody) return name;
  const char* unit = q == Quantity::Speed ? "m/s" : q == Quantity::Density ? "kg/m³" : q == Quantity::Pressure ? "Pa" : "kg";
  return fmt::format("{} ({})", name, unit);
}

// One pixel per step along the longer axis, from a to b.
void draw_segment(Image& image, const Camera& camera, const Vec3d& a, const Vec3d& b, Color color, float alpha) {
  const auto pa = camera.project(a), pb = camera.project(b);
  if (!pa || !pb) return;
  const double dx = pb->x - pa->x, dy = pb->y - pa->y;
  const double steps = std::min(std::ceil(std::max(std::abs(dx), std::abs(dy))), 1e5);
  for (double s = 0; s <= steps; ++s) {
    const double f = steps > 0 ? s / steps : 0;
    image.blend(static_cast<int>(std::floor(pa->x + f * dx)), static_cast<int>(std::floor(pa->y + f * dy)), color, alpha);
  }
}

void draw_box_edges(Image& image, const Camera& camera, const Box<double>& box) {
  for (int axis = 0; axis < 3; ++axis)
    for (int corner = 0; corner < 4; ++corner) {
      Vec3d a = box.lo, b = box.lo;
      const int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
      a[o1] = b[o1] = (corner & 1) ? box.hi[o1] : box.lo[o1];
      a[o2] = b[o2] = (corner & 2) ? box.hi[o2] : box.lo[o2];
      b[axis] = box.hi[axis];
      draw_segment(image, camera, a, b, kEdge, 0.8f);
    }
}

// Smoothing of the surface density: adaptive, about 32 particles per kernel,
// from 2 px (on a 720-line picture) in the cores up to 1/20 of the height.
DensityKernel density_kernel(int height) {
  DensityKernel k;
  k.min_px = std::max(1.0, height / 360.0);
  k.neighbours = 32;
  k.max_px = std::max(k.min_px, height / 20.0);
  return k;
}

std::string tick_label(double v, bool log_density) {
  if (log_density) return fmt::format("{:.2g}", std::pow(10.0, v));
  return fmt::format("{:.4g}", v);
}

}  // namespace

RunInfo read_run(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) throw io::IoError(dir.string() + ": no such run directory");
  RunInfo run;
  run.dir = dir;
  const fs::path pvd = dir / "particles.pvd";
  if (fs::exists(pvd)) {
    run.frames = io::read_pvd(pvd);
  } else {
    // The .vtp frames, or else the HDF5 snapshots (their times from their headers).
    for (const char* extension : {".vtp", ".h5"}) {
      std::vector<std::string> names;
      for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file() && e.path().extension() == extension && io::frame_index(e.path(), io::kParticleSeries))
          names.push_back(e.path().filename().string());
      std::sort(names.begin(), names.end());
      for (auto& n : names) {
        const double time = std::string_view(extension) == ".h5" ? io::read_snapshot_layout(dir / n).time : 0.0;
        run.frames.push_back({time, std::move(n)});
      }
      if (!run.frames.empty()) break;
    }
  }
  if (run.frames.empty())
    throw io::IoError(dir.string() + ": no frames to render (no particles.pvd, particles_*.vtp or particles_*.h5); make "
                      "them with: swirl run SCENE --out " + dir.string());
  const fs::path scene_file = dir / "scene.toml";
  if (fs::exists(scene_file)) {
    // parse_scene on io's checked read: the scene loader's own read would block on a FIFO.
    const scene::Scene s = scene::parse_scene(io::read_regular_file(scene_file, io::kMaxSceneBytes), scene_file.string());
    RunInfo from_scene = run_info_of(s);
    from_scene.dir = run.dir;
    from_scene.frames = std::move(run.frames);
    run = std::move(from_scene);
  }
  run.scene_name = fs::absolute(dir).lexically_normal().filename().string();
  if (run.scene_name.empty()) run.scene_name = fs::absolute(dir).lexically_normal().parent_path().filename().string();
  return run;
}

RunInfo run_info_of(const scene::Scene& s) {
  RunInfo run;
  run.has_scene = true;
  run.nbody = s.nbody.has_value();
  if (s.walls && !run.nbody) run.box = s.box;
  run.gravity = s.gravity;
  if (s.sph) run.rest_density = s.sph->rest_density;
  run.surface = fluid_surface_of(s);
  return run;
}

std::filesystem::path png_path_for(const std::filesystem::path& out_dir, const std::filesystem::path& frame_file) {
  return out_dir / (frame_file.stem().string() + ".png");
}

namespace {
Frame first_frame(const RunInfo& run) {
  if (run.frames.empty()) throw io::IoError(run.dir.string() + ": no frames to render");
  return load_frame(run.dir / run.frames.front().file);
}
}  // namespace

RunRenderer::RunRenderer(RunInfo run, RenderOptions options) : RunRenderer(first_frame(run), run, options) {}

RunRenderer::RunRenderer(const Frame& whole_first, RunInfo run, RenderOptions options)
    : run_(std::move(run)), options_(options) {
  if (options_.width < 64 || options_.height < 64 || options_.width > 16384 || options_.height > 16384)
    throw std::invalid_argument(fmt::format("picture size {}x{}: each side must be between 64 and 16384 pixels",
                                            options_.width, options_.height));
  if (options_.range && !(options_.range->second > options_.range->first))
    throw std::invalid_argument("colour range: the upper end must be above the lower end");
  quantity_ = options_.color.value_or(run_.nbody ? Quantity::Density : Quantity::Speed);
  log_density_ = run_.nbody && quantity_ == Quantity::Density;
  if (options_.surface && run_.nbody && !(run_.rest_density > 0))
    throw std::invalid_argument("--surface draws a fluid's surface, and this is a gravity run with no [sph] fluid; "
                                "draw it without --surface");
  if (options_.surface) log_density_ = false;
  if (whole_first.positions.empty()) throw io::IoError(whole_first.file.string() + ": the frame has no particles");
  // A run that starts without fluid (a tap filling an empty tank) takes its scales from the whole frame.
  const Frame fluid = fluid_part(whole_first);
  const Frame& first = fluid.positions.empty() ? whole_first : fluid;

  const int bar_area = std::min(std::max(190, options_.width / 6), options_.width / 3);
  plot_width_ = options_.width - bar_area;
  bounds_ = run_.box ? *run_.box : robust_bounds(first.positions);
  const Projection projection =
      options_.projection.value_or(options_.view == View::Iso ? Projection::Perspective : Projection::Orthographic);
  camera_ = Camera::fit(bounds_, options_.view, projection, 0, 0.1 * options_.height, plot_width_, 0.88 * options_.height);

  // Splats overlap a little: 0.6 of the spacing of a fluid lattice (m/ρ = s³),
  // else of the mean spacing in the bounds.
  double volume_per_particle = 0;
  if (first.mass.size() == first.positions.size() && first.density.size() == first.positions.size()) {
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < first.mass.size(); ++i)
      if (first.density[i] > 0) { sum += first.mass[i] / first.density[i]; ++count; }
    if (count == first.mass.size()) volume_per_particle = sum / static_cast<double>(count);
  }
  splat_radius_ = volume_per_particle > 0 ? 0.6 * std::cbrt(volume_per_particle)
                                          : 0.35 * std::cbrt(bounds_.volume() / static_cast<double>(first.positions.size()));

  if (options_.range) {
    range_ = *options_.range;
  } else if (log_density_) {
    std::vector<double> masses = first.mass.size() == first.positions.size()
                                     ? first.mass
                                     : std::vector<double>(first.positions.size(), 1.0 / static_cast<double>(first.positions.size()));
    const DensityMap map = surface_density(camera_, options_.width, options_.height, first.positions, masses,
                                           density_kernel(options_.height));
    const double peak = *std::max_element(map.sigma.begin(), map.sigma.end());
    const double hi = peak > 0 ? std::log10(peak) : 1.0;
    range_ = {hi - kLogDecades, hi};
  } else {
    const std::vector<double> values = quantity_values(first, quantity_);
    double lo = quantile(values, kLowQuantile), hi = quantile(values, kHighQuantile);
    if (!(hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi)))) {
      // The first frame shows one value (speed at rest): take the scale from the scene.
      const double g = norm(run_.gravity);
      const double height = run_.box ? run_.box->extent().z : 0;
      if (quantity_ == Quantity::Speed && g > 0 && height > 0) {
        lo = 0, hi = std::sqrt(2 * g * height);
      } else if (quantity_ == Quantity::Pressure && run_.rest_density > 0 && g > 0 && height > 0) {
        lo = 0, hi = run_.rest_density * g * height;
      } else if (quantity_ == Quantity::Density && run_.rest_density > 0) {
        lo = 0.97 * run_.rest_density, hi = 1.03 * run_.rest_density;
      } else if (lo == 0) {
        lo = 0, hi = 1;
      } else {
        const double v = lo;
        lo = v - 0.1 * std::abs(v), hi = v + 0.1 * std::abs(v);
      }
    }
    range_ = {lo, hi};
  }
}

Image RunRenderer::render(const Frame& frame) const {
  const int W = options_.width, H = options_.height;
  Image image(W, H, kBackground);
  const ColorMap map = log_density_ ? ColorMap::Inferno : ColorMap::Viridis;
  if (log_density_) {
    const std::vector<double> masses =
        frame.mass.size() == frame.positions.size()
            ? frame.mass
            : std::vector<double>(frame.positions.size(), 1.0 / static_cast<double>(std::max<std::size_t>(frame.positions.size(), 1)));
    const DensityMap density = surface_density(camera_, W, H, frame.positions, masses, density_kernel(H));
    draw_log_density(image, density, map, range_.first, range_.second);
  } else if (options_.surface) {
    if (run_.box) draw_box_edges(image, camera_, *run_.box);
    draw_water(image, camera_, frame_surface(frame, run_.surface));
  } else {
    if (run_.box) draw_box_edges(image, camera_, *run_.box);
    SplatStyle style;
    style.map = map;
    style.lo = range_.first;
    style.hi = range_.second;
    style.radius = splat_radius_;
    std::vector<double> values = quantity_values(frame, quantity_);
    if (frame.kind.empty()) {
      draw_splats(image, camera_, frame.positions, values, style);
    } else {
      // Boundary particles: the box walls' are left to the box's edges (drawn,
      // they would hide the fluid behind the near wall); an obstacle's are
      // drawn as a solid, in one grey (a NaN value, SplatStyle::solid).
      std::vector<Vec3d> shown;
      std::vector<double> shown_values;
      for (std::size_t i = 0; i < frame.positions.size(); ++i) {
        const bool boundary = is_boundary(frame.kind[i]);
        if (boundary && run_.box && !strictly_inside(*run_.box, frame.positions[i])) continue;
        shown.push_back(frame.positions[i]);
        shown_values.push_back(boundary ? std::numeric_limits<double>::quiet_NaN() : values[i]);
      }
      draw_splats(image, camera_, shown, shown_values, style);
    }
  }

  // The colour bar on a plain panel at the right, top = high.
  const Color panel = log_density_ ? colormap(map, 0.0) : kBackground;
  for (int y = 0; y < H; ++y)
    for (int x = plot_width_; x < W; ++x) image.at(x, y) = panel;
  const int title_px = std::max(10, H / 36), tick_px = std::max(9, H / 45);
  if (options_.surface) {
    font_.draw(image, "water surface", plot_width_ + std::max(8, W / 120), H / 5 - title_px * 2, title_px, kText);
    font_.draw(image, fmt::format("colour field at {:g}", run_.surface.iso), plot_width_ + std::max(8, W / 120),
               H / 5 - title_px * 2 + title_px + title_px / 3, tick_px, kText);
  }
  const int bar_x0 = plot_width_ + std::max(12, W / 80), bar_w = std::max(12, W / 70);
  const int bar_y0 = H / 5, bar_y1 = H - H / 6;
  for (int y = bar_y0; y <= bar_y1 && !options_.surface; ++y) {
    const Color c = colormap(map, static_cast<double>(bar_y1 - y) / (bar_y1 - bar_y0));
    for (int x = bar_x0; x < bar_x0 + bar_w; ++x) image.at(x, y) = c;
  }
  const int ticks = 5;
  for (int k = 0; k < ticks && !options_.surface; ++k) {
    const double f = static_cast<double>(k) / (ticks - 1);
    const int y = bar_y1 - static_cast<int>(std::lround(f * (bar_y1 - bar_y0)));
    for (int x = bar_x0 + bar_w; x < bar_x0 + bar_w + 5; ++x) image.blend(x, y, kText, 1.0f);
    font_.draw(image, tick_label(range_.first + f * (range_.second - range_.first), log_density_), bar_x0 + bar_w + 8,
               y + tick_px / 2 - 1, tick_px, kText);
  }
  const std::string title = options_.surface ? std::string() : quantity_title(quantity_, run_.nbody, log_density_);
  if (!title.empty()) font_.draw(image, title, plot_width_ + std::max(8, W / 120), bar_y0 - title_px * 2, title_px, kText);
  if (log_density_ || run_.nbody)
    font_.draw(image, log_density_ ? "mass / length², log scale" : "G = 1 units", plot_width_ + std::max(8, W / 120),
               bar_y0 - title_px * 2 + title_px + title_px / 3, tick_px, kText);

  // The time in the top-left corner, and what this is below it.
  const int time_px = std::max(12, H / 24);
  const std::string time = run_.nbody ? fmt::format("t = {:.2f}", frame.time) : fmt::format("t = {:.3f} s", frame.time);
  font_.draw(image, time, time_px / 2, time_px + time_px / 3, time_px, kText);
  const auto boundary = static_cast<std::size_t>(std::count_if(frame.kind.begin(), frame.kind.end(), is_boundary));
  const std::string caption =
      boundary ? fmt::format("{} · {} particles + {} boundary", run_.scene_name, frame.positions.size() - boundary, boundary)
               : fmt::format("{} · {} particles", run_.scene_name, frame.positions.size());
  font_.draw(image, caption, time_px / 2, time_px * 2 + tick_px / 2 + 2, tick_px, Color{0.7f, 0.7f, 0.72f});
  return image;
}

void RunRenderer::render_file(const std::filesystem::path& frame_file, const std::filesystem::path& png) const {
  write_png(png, render(load_frame(frame_file)));
}

}  // namespace swirl::render

namespace swirl::render {

sim::FrameHook render_every(std::filesystem::path run_dir, std::uint64_t every, RenderOptions options) {
  if (every == 0) throw std::invalid_argument("render every 0 frames: give at least 1");
  auto renderer = std::make_shared<std::unique_ptr<RunRenderer>>();
  return [run_dir = std::move(run_dir), every, options, renderer](const std::filesystem::path& frame, double,
                                                                  const sim::ClaimFile& claim) {
    const auto number = io::frame_index(frame, io::kParticleSeries);
    if (!number || *number % every != 0) return;
    // A .vtp or .h5 frame (the first format written); CSV frames hold too little to draw.
    std::filesystem::path drawn = frame;
    for (const char* extension : {".vtp", ".h5"}) {
      drawn.replace_extension(extension);
      if (std::filesystem::exists(drawn)) break;
    }
    if (!std::filesystem::exists(drawn))
      throw io::IoError(frame.string() + ": rendering needs .vtp or .h5 frames (output.format must include \"vtp\" "
                        "or \"hdf5\")");
    if (!*renderer) *renderer = std::make_unique<RunRenderer>(read_run(run_dir), options);
    const std::filesystem::path out = run_dir / "render";
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec) throw io::IoError(out.string() + ": cannot create (" + ec.message() + ")");
    (*renderer)->render_file(drawn, claim(png_path_for(out, drawn)));
  };
}

}  // namespace swirl::render
