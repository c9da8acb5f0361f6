#include "swirl/view/mesher.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "json.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::view {

Mesher::Mesher(render::FluidSurface settings, std::function<void(std::shared_ptr<const std::string>)> publish,
               std::function<void(const std::string&)> log)
    : settings_(settings), publish_(std::move(publish)), log_(std::move(log)) {
  const auto positive = [](double x) { return x > 0 && std::isfinite(x); };
  if (!positive(settings_.cell))
    throw std::invalid_argument(fmt::format("swirl view: the surface's cell must be > 0 particle spacings, got {}", settings_.cell));
  if (!positive(settings_.radius))
    throw std::invalid_argument(fmt::format("swirl view: the surface's kernel radius must be > 0, got {}", settings_.radius));
  if (!(settings_.iso > 0 && settings_.iso < 1))
    throw std::invalid_argument(fmt::format("swirl view: the surface's iso level must be in (0, 1), got {}", settings_.iso));
  thread_ = std::thread([this] { loop(); });
}

Mesher::~Mesher() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool Mesher::busy() const {
  std::lock_guard lock(mutex_);
  return working_ || waiting_.has_value();
}

void Mesher::offer(MeshInput input) {
  if (!input.frame) throw std::invalid_argument("Mesher::offer: no state");
  const std::size_t n = input.frame->x.size();
  if (input.frame->y.size() != n || input.frame->z.size() != n || input.volumes.size() != n)
    throw std::invalid_argument("Mesher::offer: the positions and volumes differ in length");
  {
    std::lock_guard lock(mutex_);
    waiting_ = std::move(input);
  }
  wake_.notify_all();
}

MesherStats Mesher::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

render::SurfaceMesh Mesher::mesh_of(const MeshInput& input, const render::FluidSurface& settings) {
  const FrameData& f = *input.frame;
  std::vector<Vec3d> positions;
  std::vector<double> volumes;
  positions.reserve(f.x.size());
  volumes.reserve(f.x.size());
  for (std::size_t i = 0; i < f.x.size(); ++i)
    if (input.volumes[i] > 0) {
      positions.push_back({double(f.x[i]), double(f.y[i]), double(f.z[i])});
      volumes.push_back(input.volumes[i]);
    }
  return render::particle_surface(positions, volumes, settings);
}

void Mesher::loop() {
  // This thread's loops never take the pool from the solver (see the header).
  parallel::SerialScope serial;
  for (;;) {
    MeshInput input;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return quit_ || waiting_.has_value(); });
      if (quit_) return;
      input = std::move(*waiting_);
      waiting_.reset();
      working_ = true;
    }
    const auto t0 = std::chrono::steady_clock::now();
    std::shared_ptr<const std::string> message;
    render::SurfaceMesh mesh;
    std::string error;
    try {
      mesh = mesh_of(input, settings_);
      message = std::make_shared<const std::string>(encode_mesh(mesh, input.frame->step, input.frame->time));
    } catch (const std::exception& e) {
      error = e.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Counted before it is published, so that whoever has the message sees it
    // in stats(); not busy only once it is published.
    std::uint64_t failed = 0;
    {
      std::lock_guard lock(mutex_);
      if (message) {
        ++stats_.meshes;
        stats_.seconds += seconds;
        stats_.max_seconds = std::max(stats_.max_seconds, seconds);
        stats_.bytes += message->size();
        stats_.vertices = mesh.vertices.size();
        stats_.triangles = mesh.triangle_count();
      } else {
        failed = ++stats_.failed;
      }
    }
    if (message) publish_(message);
    {
      std::lock_guard lock(mutex_);
      working_ = false;
    }
    std::uint64_t power = 1;
    while (power < failed) power *= 10;
    if (failed > 0 && power == failed && log_)
      log_(fmt::format("swirl view: the surface of step {} was not made: {} ({} so far)", input.frame->step, error,
                       failed));
  }
}

std::string mesher_json(const Mesher* mesher) {
  if (!mesher) return "null";
  const MesherStats s = mesher->stats();
  return fmt::format(R"({{"meshes":{},"ms":{},"vertices":{},"triangles":{}}})", s.meshes,
                     json::number(s.meshes ? 1e3 * s.seconds / double(s.meshes) : 0.0), s.vertices, s.triangles);
}

}  // namespace swirl::view
