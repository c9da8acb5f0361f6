// swirl._swirl: the module's exceptions and threads; the rest in scene.cpp,
// simulation.cpp and run.cpp (bindings.hpp).
#include <stdexcept>

#include <nanobind/stl/string.h>

#include "bindings.hpp"
#include "swirl/config.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/blow_up.hpp"

namespace swirl::python {

NB_MODULE(_swirl, m) {
  m.doc() = "swirl's engine (C++); use the package swirl, which wraps it";

  // The C++ exceptions, as Python exceptions deriving from the built-in that fits.
  nb::exception<scene::SceneError>(m, "SceneError", PyExc_ValueError);
  nb::exception<SimulationError>(m, "SimulationError", PyExc_RuntimeError);
  nb::exception<io::IoError>(m, "IoError", PyExc_OSError);

  m.def("thread_count", [] { return parallel::thread_count(); });
  m.def("max_thread_count", [] { return parallel::max_thread_count(); });
  m.def("set_thread_count", [](int n) { parallel::set_thread_count(n); }, nb::arg("n"));
  m.attr("__version__") = SWIRL_VERSION;

  bind_scene(m);
  bind_simulation(m);
  bind_run(m);
  bind_render(m);
  bind_cli(m);
}

}  // namespace swirl::python
