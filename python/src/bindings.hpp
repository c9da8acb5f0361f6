// The C++ side of the Python module swirl (python/swirl/ is the Python side,
// docs/python.md the user's page). This layer is thin and private (every name
// it binds is reached through the Python classes, which carry the docstrings):
//   scene.cpp       scenes from files and TOML text: scene/load.hpp, nothing else
//   simulation.cpp  a Simulation<float|double> built by sim/build.hpp, stepped
//                   with the GIL released, its fields as zero-copy numpy arrays
//   run.cpp         sim::run_scene (frames, diagnostics, checkpoints, resume) as
//                   `swirl run` calls it, and the summary as a dict
//   render.cpp      a run folder's frame drawn as `swirl render` draws it, and a
//                   simulation's current state drawn the same way
//   cli.cpp         the whole command-line tool in-process (swirl.cli, swirl.bench)
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nanobind/nanobind.h>

#include "swirl/render/run_renderer.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl {
template <class Real>
class Simulation;
}  // namespace swirl

namespace swirl::python {

namespace nb = nanobind;

// Forces written in Python: (phase name, fn(t)) pairs (python/swirl/_simulation.py's _forces()).
using Forces = std::vector<std::pair<std::string, nb::object>>;

// simulation.cpp: a run's simulation (swirl.run with forces or a callback) as
// a _swirl.Simulation object that does not own it, with the Python forces
// added as solvers; detach_simulation() cuts the object off when the run ends
// (every later use raises). Call both with the GIL held.
template <class Real>
nb::object borrow_simulation(Simulation<Real>& sim, const scene::Scene& scene, const Forces& forces);
void detach_simulation(nb::handle native);

// simulation.cpp: a _swirl.Simulation's current state as a picture's frame,
// and what its scene says for pictures (render.cpp draws them).
render::Frame simulation_frame(nb::handle native);
render::RunInfo simulation_run_info(nb::handle native);

// A validated scene, as the loader returns it.
struct PyScene {
  scene::Scene scene;
};

void bind_scene(nb::module_& m);
void bind_simulation(nb::module_& m);
void bind_run(nb::module_& m);
void bind_render(nb::module_& m);
void bind_cli(nb::module_& m);

// Raises KeyboardInterrupt (or whatever a signal handler raised) if a signal
// arrived. Call with the GIL held, between steps.
inline void check_signals() {
  if (PyErr_CheckSignals() != 0) throw nb::python_error();
}

}  // namespace swirl::python
