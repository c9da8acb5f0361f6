#include "swirl/sim/run.hpp"

#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "swirl/force/uniform_gravity.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/csv.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::sim {
namespace {

// Writes frames in the scene's formats and keeps the .pvd series current.
template <class Real>
class FrameWriter {
 public:
  FrameWriter(const scene::Scene& scene, const std::filesystem::path& dir)
      : scene_(scene), dir_(dir), series_(dir / "particles.pvd") {}

  void write(const ParticleSet<Real>& p, double time) {
    for (auto format : scene_.formats) {
      if (format == scene::OutputFormat::Vtp) {
        const std::string name = fmt::format("particles_{:06d}.vtp", frames_);
        io::write_vtp(dir_ / name, p, time);
        series_.add(time, name);
      } else {
        io::write_csv(dir_ / fmt::format("particles_{:06d}.csv", frames_), p, time);
      }
    }
    ++frames_;
  }
  std::size_t frames() const { return frames_; }

 private:
  const scene::Scene& scene_;
  std::filesystem::path dir_;
  io::PvdSeries series_;
  std::size_t frames_ = 0;
};

template <class Real>
std::size_t bytes_per_particle(const ParticleSet<Real>& p) {
  std::size_t bytes = sizeof(std::uint64_t);  // id
  for (const auto& f : p.fields()) bytes += static_cast<std::size_t>(f.components) * sizeof(Real);
  return bytes;
}

template <class Real>
RunSummary run_typed(const scene::Scene& scene, const RunOptions& options,
                     const std::function<void(const RunProgress&)>& on_progress) {
  RunSummary summary;
  summary.scene_file = scene.file;
  summary.precision = std::is_same_v<Real, float> ? "float" : "double";
  summary.out_dir = options.out_dir;
  summary.threads = parallel::thread_count();

  SimulationSettings settings;
  settings.dt = scene.dt;
  settings.block_size = scene.block_size;
  settings.box = boundary::BoxCollision<double>{scene.box, scene.restitution};
  Simulation<Real> sim(scene::make_particles<Real>(scene), settings);
  sim.add_force(std::make_unique<UniformGravity<Real>>(scene.gravity.template cast<Real>()));
  summary.particles = sim.particles().size();
  summary.bytes_per_particle = bytes_per_particle(sim.particles());

  const std::uint64_t total = options.steps.value_or(scene.total_steps());
  FrameWriter<Real> writer(scene, options.out_dir);
  const auto started = std::chrono::steady_clock::now();
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(); };
  auto write_frame = [&] {
    ScopedPhase phase(sim.timers(), "output");
    writer.write(sim.particles(), sim.time());
  };

  // Frame k is due at the first step with time ≥ k·interval; the slack keeps
  // k·interval that lands on a step (up to rounding) on that step.
  const double interval = scene.output_interval;
  const double slack = 1e-9 * scene.dt;
  std::uint64_t next_frame = 1;
  sim.start();
  write_frame();
  bool last_written = true;
  if (on_progress) on_progress({0, total, 0.0, wall()});
  try {
    for (std::uint64_t s = 0; s < total; ++s) {
      sim.step();
      last_written = false;
      if (interval > 0 && sim.time() + slack >= static_cast<double>(next_frame) * interval) {
        write_frame();
        last_written = true;
        next_frame = static_cast<std::uint64_t>(std::floor((sim.time() + slack) / interval)) + 1;
      }
      if (on_progress) on_progress({sim.step_count(), total, sim.time(), wall()});
    }
    if (!last_written) write_frame();
  } catch (const SimulationError& e) {
    summary.error = e.what();
  } catch (const io::IoError& e) {
    summary.error = fmt::format("writing output failed at step {}: {}", sim.step_count(), e.what());
  }

  summary.steps = sim.step_count();
  summary.sim_time = sim.time();
  summary.wall_seconds = wall();
  summary.steps_per_second = summary.wall_seconds > 0 ? static_cast<double>(summary.steps) / summary.wall_seconds : 0;
  summary.phases = sim.timers().phases();
  summary.frames = writer.frames();
  return summary;
}

}  // namespace

RunSummary run_scene(const scene::Scene& scene, const RunOptions& options,
                     const std::function<void(const RunProgress&)>& on_progress) {
  io::ensure_writable_directory(options.out_dir);
  if (options.threads > 0) parallel::set_thread_count(options.threads);
  return scene.precision == scene::Precision::Float ? run_typed<float>(scene, options, on_progress)
                                                    : run_typed<double>(scene, options, on_progress);
}

}  // namespace swirl::sim
