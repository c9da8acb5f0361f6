// view_scene(): a scene run live for the browser (`swirl view SCENE`).
//
// Three threads: the simulation steps as fast as it can (or at the page's
// speed) on the run's worker threads; an encoder turns the newest copied
// state into a frame (view/wire.hpp) off the simulation's path; the server
// (view/live_server.hpp) sends it. The simulation copies positions and the
// coloured field only when the encoder is idle and a frame is due (fps), so a
// viewer costs it one copy per frame and never a wait. A fourth, the mesher
// (view/mesher.hpp; SPH scenes), makes the fluid's surface mesh from the same
// copy (with each particle's volume, copied then too) while some viewer has
// the surface on and the mesher is free.
//
// Controls from the page act between steps: pause, resume, one step, reset
// (the scene built again from its start), a speed cap, the field that colours
// the particles, the surface (on for a viewer: the surface of the state shown
// now, also while paused), the mouse's push: an external force (PushForce, a solver
// like any other) a = strength·(v_drag − v)·(1 − r/R) on the particles within
// R of the point, which drags the fluid along with the pointer, and the live
// parameters (view/parameters.hpp: viscosity, gravity, softening), each change
// checked against its key's range, applied to the solver on the simulation's
// thread and logged with the step and time it took effect at; a reset rebuilds
// the scene with the values changed so far. A live run
// writes no run folder; a blow-up pauses it with the message shown on the page
// (reset starts over). At the scene's end time it pauses.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "swirl/scene/scene.hpp"
#include "swirl/view/live_server.hpp"
#include "swirl/view/mesher.hpp"

namespace swirl::view {

struct ViewOptions {
  ServerOptions server;
  int threads = 0;        // worker threads of the simulation (0: OpenMP's default)
  double fps = 30;        // frames per second sent at most
  bool start_paused = false;
  bool surface = false;       // every viewer starts with the surface on (SPH scenes and runs only)
  // The surface mesh's grid cell, in particle spacings: coarser than a run's
  // output.surface_cell (½), so that a mesh is made in a frame or two
  // (docs/performance/view.md); its kernel radius and level are the scene's
  // output.surface_radius and output.surface_iso.
  double surface_cell = 1.0;
  const std::atomic<bool>* stop = nullptr;  // set (by a signal, or a test) to end the session
  std::function<void(const std::string&)> log;
  // Called once the server listens (the CLI prints the URL; tests connect).
  std::function<void(const LiveServer&)> on_listening;
};

struct ViewResult {
  std::uint64_t steps = 0;    // steps taken in the session (over resets)
  std::uint64_t resets = 0;
  std::uint64_t parameter_changes = 0;  // live parameter values applied
  std::uint64_t refused = 0;            // controls refused by the session (a value out of range, a seek past the end)
  double wall_seconds = 0;
  double setup_seconds = 0;   // of which building the simulation before the first step (replay: reading the first frame)
  std::uint64_t frames_read = 0;  // replay: frame files read (steps: frames shown)
  double read_seconds = 0;        // replay: time spent reading them
  ServerStats server;
  MesherStats mesher;             // the surface meshes made (none unless a viewer turned the surface on)
};

// The server's options of a session: options.server, new viewers starting
// with the surface on when options.surface.
ServerOptions server_options(const ViewOptions& options);

// Runs until *options.stop; throws std::runtime_error when the server cannot
// listen, std::invalid_argument for options.surface on a scene without [sph].
ViewResult view_scene(const scene::Scene& scene, const ViewOptions& options);

}  // namespace swirl::view
