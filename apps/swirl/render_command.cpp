// `swirl render`: pictures (PNG) of a run's frames, and a movie with ffmpeg.
//
//   swirl render RUN_DIR [--frame K | --all] [--view front|top|iso] [--projection ortho|perspective]
//                [--color speed|density|pressure|mass] [--size WxH] [--range LO,HI] [--out DIR]
//                [--surface] [--movie] [--fps N] [--threads N]
//
// Without --frame or --all the last frame is drawn. Pictures go to
// RUN_DIR/render/particles_NNNNNN.png (or --out DIR), the movie to
// DIR/movie.mp4. Every file is written atomically.
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "commands.hpp"
#include "flags.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/render/movie.hpp"
#include "swirl/render/run_renderer.hpp"

namespace swirl::cli {
namespace {

struct RenderArgs {
  std::string run_dir;
  std::int64_t frame = -1;
  bool all = false;
  std::string view = "front";
  std::string projection;
  std::string color;
  std::string size = "1280x720";
  std::string range;
  std::string out;
  bool surface = false;
  bool movie = false;
  int fps = 25;
  int threads = 0;
};

std::pair<int, int> parse_size(const std::string& text) {
  const auto x = text.find('x');
  try {
    std::size_t used_w = 0, used_h = 0;
    if (x == std::string::npos) throw std::invalid_argument("");
    const int w = std::stoi(text.substr(0, x), &used_w), h = std::stoi(text.substr(x + 1), &used_h);
    if (used_w != x || used_h != text.size() - x - 1) throw std::invalid_argument("");
    return {w, h};
  } catch (const std::logic_error&) {
    throw std::invalid_argument("--size '" + text + "': expected WIDTHxHEIGHT in pixels, e.g. 1280x720");
  }
}

std::pair<double, double> parse_range(const std::string& text) {
  const auto sep = text.find_first_of(",:");
  try {
    std::size_t used_lo = 0, used_hi = 0;
    if (sep == std::string::npos) throw std::invalid_argument("");
    const double lo = std::stod(text.substr(0, sep), &used_lo), hi = std::stod(text.substr(sep + 1), &used_hi);
    if (used_lo != sep || used_hi != text.size() - sep - 1 || !std::isfinite(lo) || !std::isfinite(hi))
      throw std::invalid_argument("");
    return {lo, hi};
  } catch (const std::logic_error&) {
    throw std::invalid_argument("--range '" + text + "': expected LO,HI (finite numbers), e.g. 0,3.5");
  }
}

int render(const RenderArgs& args) {
  namespace fs = std::filesystem;
  render::RenderOptions options;
  options.view = render::parse_view(args.view);
  if (!args.projection.empty()) options.projection = render::parse_projection(args.projection);
  if (!args.color.empty()) options.color = render::parse_quantity(args.color);
  std::tie(options.width, options.height) = parse_size(args.size);
  if (!args.range.empty()) options.range = parse_range(args.range);
  options.surface = args.surface;
  if (args.threads > 0) parallel::set_thread_count(args.threads);
  // Refuse before drawing anything when the movie cannot be made.
  if (args.movie && !render::find_program("ffmpeg"))
    throw std::invalid_argument("--movie: " + render::ffmpeg_missing_hint() +
                                "; without --movie, --all still draws every frame as PNG");

  render::RunInfo run = render::read_run(args.run_dir);
  std::vector<io::PvdEntry> frames = run.frames;
  if (args.frame >= 0) {
    if (static_cast<std::size_t>(args.frame) >= frames.size())
      throw std::invalid_argument(fmt::format("{}: no frame {} (the run has frames 0 to {})", args.run_dir, args.frame,
                                              frames.size() - 1));
    frames = {frames[static_cast<std::size_t>(args.frame)]};
  } else if (!args.all && !args.movie) {
    frames = {frames.back()};
  }
  // A frame listed in the series but missing on disk is named at the end, not
  // a reason to stop drawing the others; the camera is fitted to the first
  // frame that exists.
  const auto on_disk = [&](const io::PvdEntry& f) { return fs::is_regular_file(fs::path(args.run_dir) / f.file); };
  std::vector<std::string> missing;
  for (const auto& f : frames)
    if (!on_disk(f)) missing.push_back(f.file);
  std::erase_if(frames, [&](const io::PvdEntry& f) { return !on_disk(f); });
  if (frames.empty())
    throw io::IoError(fmt::format("{}: frame file{} missing: {}; nothing to draw", args.run_dir,
                                  missing.size() == 1 ? " is" : "s are", fmt::join(missing, ", ")));
  std::erase_if(run.frames, [&](const io::PvdEntry& f) { return !on_disk(f); });
  // Options are checked and the first frame read before the output folder is made.
  const render::RunRenderer renderer(std::move(run), options);
  const fs::path out = args.out.empty() ? fs::path(args.run_dir) / "render" : fs::path(args.out);
  io::ensure_writable_directory(out);

  std::vector<fs::path> written;
  for (const auto& f : frames) {
    const fs::path vtp = fs::path(args.run_dir) / f.file;
    const fs::path png = render::png_path_for(out, vtp);
    renderer.render_file(vtp, png);
    written.push_back(png);
  }
  const auto [lo, hi] = renderer.range();
  const std::string colours = args.surface ? std::string("water surface")
                              : renderer.log_density_view()
                                  ? fmt::format("log surface density {:.3g} to {:.3g}", lo, hi)
                                  : fmt::format("{} {:.4g} to {:.4g}", render::quantity_name(renderer.quantity()), lo, hi);
  if (written.size() == 1)
    fmt::print("swirl render: wrote {} ({})\n", written.front().string(), colours);
  else
    fmt::print("swirl render: wrote {} frames to {} ({})\n", written.size(), out.string(), colours);
  if (!missing.empty()) {
    fmt::print(stderr, "swirl render: {} frame{} missing from {}, not drawn: {}\n", missing.size(),
               missing.size() == 1 ? " is" : "s are", args.run_dir, fmt::join(missing, ", "));
    if (args.movie) fmt::print(stderr, "swirl render: no movie: it would skip the missing frames\n");
    return 1;
  }
  if (args.movie) {
    const fs::path movie = out / "movie.mp4";
    render::make_movie(written, movie, args.fps);
    fmt::print("swirl render: wrote {} ({} frames at {} per second)\n", movie.string(), written.size(), args.fps);
  }
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, Commands& commands) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Draw a run's frames as PNG pictures (and an MP4 movie with ffmpeg)");
  cmd->add_option("run_dir", args->run_dir, "Run directory (holds particles.pvd and the .vtp frames)")->required();
  auto* frame = cmd->add_option("--frame", args->frame, "Draw frame K (default: the last)")
                    ->check(whole_number(0, std::uint64_t{1} << 62));
  cmd->add_flag("--all", args->all, "Draw every frame")->excludes(frame);
  cmd->add_option("--view", args->view, "front (along y), top (along -z) or iso")->check(CLI::IsMember({"front", "top", "iso"}));
  cmd->add_option("--projection", args->projection, "ortho or perspective (default: perspective for iso)")
      ->check(CLI::IsMember({"ortho", "perspective"}));
  cmd->add_option("--color,--colour", args->color, "speed, density, pressure or mass (default: speed; density for gravity)")
      ->check(CLI::IsMember({"speed", "density", "pressure", "mass"}));
  cmd->add_option("--size", args->size, "Picture size WIDTHxHEIGHT (default 1280x720)");
  cmd->add_option("--range", args->range, "Colour range LO,HI (log10 of the surface density for gravity runs)");
  cmd->add_option("--out,-o", args->out, "Where the pictures go (default: RUN_DIR/render)");
  cmd->add_flag("--surface", args->surface,
                "Draw the fluid as a water surface (a mesh of its colour field, docs/surface.md) instead of particles");
  cmd->add_flag("--movie", args->movie, "Also make DIR/movie.mp4 of every frame with ffmpeg (implies --all)")->excludes(frame);
  cmd->add_option("--fps", args->fps, "Movie frames per second (default 25)")->check(whole_number(1, 1000));
  cmd->add_option("--threads,-t", args->threads, "Threads (default: all cores); pictures are identical for any count")
      ->check(thread_count());
  commands.push_back({cmd, [args] { return render(*args); }});
}

}  // namespace swirl::cli
