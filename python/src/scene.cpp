// Scenes from Python: the loader of scene/load.hpp on a file or on TOML text
// (a dict becomes TOML text in python/swirl/_toml.py first), so every check
// and message is the CLI's. The Scene's figures are read-only.
#include <optional>
#include <string>
#include <vector>

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::python {

void bind_scene(nb::module_& m) {
  nb::class_<PyScene>(m, "Scene")
      .def_prop_ro("file", [](const PyScene& s) { return s.scene.file; })
      .def_prop_ro("toml", [](const PyScene& s) { return s.scene.toml; })
      .def_prop_ro("hash", [](const PyScene& s) { return scene::scene_hash(s.scene); })
      .def_prop_ro("precision",
                   [](const PyScene& s) { return std::string(s.scene.precision == scene::Precision::Float ? "float" : "double"); })
      .def_prop_ro("units", [](const PyScene& s) { return std::string(s.scene.units == scene::Units::SI ? "si" : "nbody"); })
      .def_prop_ro("dt", [](const PyScene& s) { return s.scene.dt; })
      .def_prop_ro("adaptive_dt", [](const PyScene& s) { return s.scene.adaptive_dt; })
      .def_prop_ro("end_time", [](const PyScene& s) { return s.scene.end_time; })
      .def_prop_ro("steps", [](const PyScene& s) { return s.scene.steps; })
      .def_prop_ro("total_steps", [](const PyScene& s) { return s.scene.total_steps(); })
      .def_prop_ro("output_interval", [](const PyScene& s) { return s.scene.output_interval; })
      .def_prop_ro("particle_count", [](const PyScene& s) { return scene::count_particles(s.scene); })
      .def_prop_ro("has_box", [](const PyScene& s) { return s.scene.walls; });

  m.def(
      "load_scene",
      [](const std::string& path, const std::vector<std::string>& overrides) {
        return PyScene{scene::load_scene(path, overrides)};
      },
      nb::arg("path"), nb::arg("overrides"));
  m.def(
      "parse_scene",
      [](const std::string& text, const std::string& file, const std::vector<std::string>& overrides) {
        return PyScene{scene::parse_scene(text, file, overrides)};
      },
      nb::arg("text"), nb::arg("file"), nb::arg("overrides"));
}

}  // namespace swirl::python
