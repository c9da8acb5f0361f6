// Mesher: the thread that makes a view session's surface meshes, off the
// simulation's threads (`swirl view --surface`, the page's "surface" box).
//
// The session offers it a state: the positions it already copied for the
// frame (a shared FrameData, view/wire.hpp) and one volume per particle
// (m/ρ0, 0 for a boundary particle, which is left out). The mesher keeps only
// the newest state it has not started; it makes that state's mesh
// (render::particle_surface, render/fluid_surface.hpp: the colour field's
// iso-surface, in the session's FluidSurface settings), encodes it (the
// "SWVM" message, view/wire.hpp) and hands it to `publish`
// (LiveServer::publish_mesh). So the session never waits for a mesh: a state
// offered while one is being made waits for the mesher (or is replaced by a
// newer one), and meshes follow the run at the rate the mesher keeps up with.
//
// Its loops run on its own thread alone (parallel::SerialScope): through the
// pool they would take the solver's workers whenever the simulation is
// between two passes. The mesh is the same either way (surface_mesh.hpp:
// bit-identical for any thread count). A mesh that cannot be made (a
// position that is not finite after a blow-up) is skipped and logged (the
// 1st, 10th, 100th, ...).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "swirl/render/fluid_surface.hpp"
#include "swirl/view/wire.hpp"

namespace swirl::view {

struct MeshInput {
  std::shared_ptr<const FrameData> frame;  // step, time and positions (x, y, z)
  std::vector<double> volumes;             // one per particle of frame; ≤ 0: not fluid, left out
};

struct MesherStats {
  std::uint64_t meshes = 0, failed = 0;
  double seconds = 0, max_seconds = 0;  // making and encoding the meshes
  std::uint64_t bytes = 0;              // of the messages
  std::size_t vertices = 0, triangles = 0;  // of the last mesh
};

class Mesher {
 public:
  // Throws std::invalid_argument naming the setting for a cell or kernel
  // radius that is not positive and finite, or an iso level outside (0, 1).
  Mesher(render::FluidSurface settings, std::function<void(std::shared_ptr<const std::string>)> publish,
         std::function<void(const std::string&)> log);
  ~Mesher();  // finishes the mesh being made, drops a waiting state
  Mesher(const Mesher&) = delete;
  Mesher& operator=(const Mesher&) = delete;

  // True while a mesh is being made or a state waits: an offer now would wait.
  bool busy() const;
  // The newest state to mesh (replaces one that waits). Throws
  // std::invalid_argument when the volumes do not match the positions.
  void offer(MeshInput input);
  MesherStats stats() const;

  // The mesh of a state, as the thread makes it (tests, and the message's content).
  static render::SurfaceMesh mesh_of(const MeshInput& input, const render::FluidSurface& settings);

 private:
  void loop();

  render::FluidSurface settings_;
  std::function<void(std::shared_ptr<const std::string>)> publish_;
  std::function<void(const std::string&)> log_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<MeshInput> waiting_;
  bool working_ = false, quit_ = false;
  MesherStats stats_;
  std::thread thread_;
};

// The statuses' "surface": {"meshes": made, "ms": mean time a mesh,
// "vertices", "triangles": the last one's}; null without a mesher.
std::string mesher_json(const Mesher* mesher);

}  // namespace swirl::view
