#include "swirl/sim/run.hpp"

#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/csv.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/sph/diagnostics.hpp"

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

// A CSV file with one row per output time, rewritten atomically after each row
// so that it always holds every row so far.
class CsvLog {
 public:
  CsvLog(std::filesystem::path path, std::string header) : path_(std::move(path)), text_(std::move(header) + "\n") {}
  void add(const std::vector<double>& row) {
    for (std::size_t k = 0; k < row.size(); ++k) text_ += fmt::format("{}{:.9g}", k ? "," : "", row[k]);
    text_ += "\n";
    io::write_file_atomic(path_, text_);
  }

 private:
  std::filesystem::path path_;
  std::string text_;
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

  auto built = build_simulation<Real>(scene);
  Simulation<Real>& sim = built.sim;
  const sph::SphFluid<Real>* fluid = built.fluid;
  const gravity::GravityForce<Real>* self_gravity = built.self_gravity;
  std::optional<CsvLog> diagnostics;
  if (fluid)
    diagnostics.emplace(options.out_dir / "diagnostics.csv",
                        "time,kinetic_energy,potential_energy,momentum_x,momentum_y,momentum_z,"
                        "mean_density_error,max_density_error,mean_neighbours");
  else if (self_gravity)
    diagnostics.emplace(options.out_dir / "diagnostics.csv",
                        "time,kinetic_energy,potential_energy,total_energy,relative_energy_error,momentum_x,"
                        "momentum_y,momentum_z,angular_momentum_x,angular_momentum_y,angular_momentum_z,virial_ratio,"
                        "mean_nodes_visited");
  std::optional<double> initial_energy;  // gravity runs: E at t = 0
  double energy_error = 0;
  summary.particles = sim.particles().size();

  const std::uint64_t total = options.steps.value_or(scene.total_steps());
  FrameWriter<Real> writer(scene, options.out_dir);
  const auto started = std::chrono::steady_clock::now();
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(); };
  auto write_frame = [&] {
    ScopedPhase phase(sim.timers(), "output");
    writer.write(sim.particles(), sim.time());
    if (fluid) {
      const auto d = sph::fluid_diagnostics(sim.particles(), scene.gravity, scene.sph->rest_density, scene.block_size);
      diagnostics->add({sim.time(), d.kinetic_energy, d.potential_energy, d.momentum.x, d.momentum.y, d.momentum.z,
                        d.mean_density_error, d.max_density_error, fluid->mean_neighbors()});
    } else if (self_gravity) {
      const auto d = gravity::diagnose(sim.particles(), scene.block_size);
      if (!initial_energy) initial_energy = d.total;
      energy_error = *initial_energy != 0 ? (d.total - *initial_energy) / std::abs(*initial_energy) : 0.0;
      diagnostics->add({sim.time(), d.kinetic, d.potential, d.total, energy_error, d.momentum.x, d.momentum.y,
                        d.momentum.z, d.angular_momentum.x, d.angular_momentum.y, d.angular_momentum.z, d.virial_ratio,
                        self_gravity->stats().mean_nodes_visited});
    }
  };
  double neighbor_sum = 0, nodes_sum = 0;  // per-evaluation means, summed for the summary

  // Frame k is due at the first step with time ≥ k·interval; the slack keeps
  // k·interval that lands on a step (up to rounding) on that step.
  const double interval = scene.output_interval;
  const double slack = 1e-9 * scene.dt;
  std::uint64_t next_frame = 1;
  sim.start();  // force models add their fields (density, potential) here
  summary.bytes_per_particle = bytes_per_particle(sim.particles());
  write_frame();
  bool last_written = true;
  if (on_progress) on_progress({0, total, 0.0, wall()});
  try {
    for (std::uint64_t s = 0; s < total; ++s) {
      sim.step();
      if (fluid) neighbor_sum += fluid->mean_neighbors();
      if (self_gravity) nodes_sum += self_gravity->stats().mean_nodes_visited;
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
  const double evaluations = static_cast<double>(summary.steps);
  if (fluid)
    summary.metrics.emplace_back("mean_neighbours", evaluations > 0 ? neighbor_sum / evaluations : fluid->mean_neighbors());
  if (self_gravity) {
    summary.metrics.emplace_back("relative_energy_error", energy_error);  // at the last frame
    summary.metrics.emplace_back("mean_nodes_visited",
                                 evaluations > 0 ? nodes_sum / evaluations : self_gravity->stats().mean_nodes_visited);
  }
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
