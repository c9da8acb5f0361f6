// Pictures of a run folder's frames, as `swirl render` draws them
// (render/run_renderer.hpp): one frame to an (height, width, 3) uint8 numpy
// image, and to a PNG when asked. The camera and colours are fixed from the
// run's first frame, as for the CLI, so pictures of one run match each other
// and the CLI's. A Simulation's current state is drawn by the same renderer
// (StateRenderer): its camera and colours fixed from the state it was made
// with, so the pictures of one simulation over time match each other.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>

#include "bindings.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/render/frame.hpp"
#include "swirl/render/png.hpp"
#include "swirl/render/run_renderer.hpp"

namespace swirl::python {
namespace {

render::RenderOptions render_options(const std::string& view, const std::optional<std::string>& projection,
                                     const std::optional<std::string>& color, int width, int height,
                                     std::optional<std::pair<double, double>> range) {
  render::RenderOptions options;
  options.view = render::parse_view(view);
  if (projection) options.projection = render::parse_projection(*projection);
  if (color) options.color = render::parse_quantity(*color);
  options.width = width, options.height = height;  // checked by RunRenderer (64 to 16384 pixels a side)
  options.range = range;
  return options;
}

// One picture: drawn with the GIL released, written to `png` when asked, and
// returned as a dict with the (height, width, 3) RGB image.
nb::dict draw(const render::RunRenderer& renderer, const render::Frame& frame, const std::optional<std::string>& png) {
  std::vector<std::uint8_t> rgb;
  int width = 0, height = 0;
  {
    nb::gil_scoped_release release;
    const render::Image image = renderer.render(frame);
    if (png) render::write_png(*png, image);
    rgb = render::to_rgb8(image);
    width = image.width(), height = image.height();
  }
  auto* owned = new std::vector<std::uint8_t>(std::move(rgb));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<std::uint8_t>*>(p); });
  const std::size_t shape[3] = {static_cast<std::size_t>(height), static_cast<std::size_t>(width), 3};
  nb::dict d;
  d["image"] = nb::ndarray<nb::numpy, std::uint8_t, nb::ndim<3>>(owned->data(), 3, shape, owner);
  d["range"] = renderer.range();
  d["quantity"] = renderer.log_density_view() ? std::string("log10 surface density")
                                              : std::string(render::quantity_name(renderer.quantity()));
  d["frame"] = frame.file.string();
  d["time"] = frame.time;
  return d;
}

nb::dict render_frame(const std::string& run_dir, int frame, const std::string& view,
                      const std::optional<std::string>& projection, const std::optional<std::string>& color, int width,
                      int height, std::optional<std::pair<double, double>> range, const std::optional<std::string>& png) {
  const render::RenderOptions options = render_options(view, projection, color, width, height, range);
  std::optional<render::RunRenderer> renderer;
  render::Frame f;
  {
    nb::gil_scoped_release release;
    render::RunInfo run = render::read_run(run_dir);
    const auto count = static_cast<int>(run.frames.size());
    const int k = frame < 0 ? count + frame : frame;
    if (k < 0 || k >= count)
      throw std::out_of_range(fmt::format("{}: no frame {} (the run has frames 0 to {})", run_dir, frame, count - 1));
    const std::filesystem::path file = std::filesystem::path(run_dir) / run.frames[static_cast<std::size_t>(k)].file;
    renderer.emplace(std::move(run), options);
    f = render::load_frame(file);
  }
  return draw(*renderer, f, png);
}

// A simulation's pictures: the camera and colours fixed from its state when made.
class StateRenderer {
 public:
  StateRenderer(nb::handle native, const render::RenderOptions& options)
      : renderer_(simulation_frame(native), simulation_run_info(native), options) {}
  nb::dict draw_state(nb::handle native, const std::optional<std::string>& png) const {
    return draw(renderer_, simulation_frame(native), png);
  }

 private:
  render::RunRenderer renderer_;
};

}  // namespace

void bind_render(nb::module_& m) {
  m.def("render_frame", &render_frame, nb::arg("run_dir"), nb::arg("frame"), nb::arg("view"),
        nb::arg("projection").none(), nb::arg("color").none(), nb::arg("width"), nb::arg("height"),
        nb::arg("range").none(), nb::arg("png").none());
  nb::class_<StateRenderer>(m, "StateRenderer")
      .def("__init__",
           [](StateRenderer* self, nb::handle native, const std::string& view,
              const std::optional<std::string>& projection, const std::optional<std::string>& color, int width,
              int height, std::optional<std::pair<double, double>> range) {
             new (self) StateRenderer(native, render_options(view, projection, color, width, height, range));
           },
           nb::arg("native"), nb::arg("view"), nb::arg("projection").none(), nb::arg("color").none(),
           nb::arg("width"), nb::arg("height"), nb::arg("range").none())
      .def("draw", &StateRenderer::draw_state, nb::arg("native"), nb::arg("png").none());
}

}  // namespace swirl::python
