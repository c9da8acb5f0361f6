#include "swirl/sim/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/checkpoint.hpp"
#include "swirl/io/csv.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
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

  // Continues after the first `frames` frames (those written before the
  // checkpoint; later ones, such as the final frame of a run that went on
  // past it, are replaced).
  void resume(std::size_t frames) {
    frames_ = frames;
    const auto pvd = dir_ / "particles.pvd";
    if (!std::filesystem::exists(pvd)) return;
    auto entries = io::read_pvd(pvd);
    if (entries.size() > frames) entries.resize(frames);
    series_.set_entries(std::move(entries));
  }

  // Writes frame number frames() and returns its first file.
  std::filesystem::path write(const ParticleSet<Real>& p, double time) {
    std::filesystem::path first;
    for (auto format : scene_.formats) {
      std::filesystem::path file;
      if (format == scene::OutputFormat::Vtp) {
        const std::string name = fmt::format("particles_{:06d}.vtp", frames_);
        file = dir_ / name;
        io::write_vtp(file, p, time);
        series_.add(time, name);
      } else {
        file = dir_ / fmt::format("particles_{:06d}.csv", frames_);
        io::write_csv(file, p, time);
      }
      if (first.empty()) first = file;
    }
    ++frames_;
    return first;
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

  // Continues an existing log, keeping its first `rows` rows.
  void resume(std::size_t rows) {
    if (!std::filesystem::exists(path_)) return;
    std::istringstream in(io::read_text_file(path_));
    std::string line;
    std::getline(in, line);  // the header, as this version writes it
    for (std::size_t k = 0; k < rows && std::getline(in, line); ++k) text_ += line + "\n";
  }
  void add(const std::vector<double>& row, std::string_view last_text_column = {}) {
    for (std::size_t k = 0; k < row.size(); ++k) text_ += fmt::format("{}{:.9g}", k ? "," : "", row[k]);
    if (!last_text_column.empty()) text_ += fmt::format(",{}", last_text_column);
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

// Named values of the run kept in checkpoints (io::CheckpointValues).
double value_of(const io::CheckpointValues& values, std::string_view name, double fallback) {
  for (const auto& [n, v] : values)
    if (n == name) return v;
  return fallback;
}

// Steps from t = 0 to time t (the same rounding as Scene::total_steps).
std::uint64_t steps_until(double t, double dt) {
  return static_cast<std::uint64_t>(std::max(0.0, std::ceil(t / dt - 1e-9)));
}

std::filesystem::path checkpoint_dir(const std::filesystem::path& out) { return out / "checkpoints"; }

// Checkpoint files, newest (highest step) first.
std::vector<std::filesystem::path> checkpoints_in(const std::filesystem::path& out) {
  std::vector<std::filesystem::path> files;
  if (!std::filesystem::is_directory(checkpoint_dir(out))) return files;
  for (const auto& e : std::filesystem::directory_iterator(checkpoint_dir(out)))
    if (e.path().extension() == ".swc") files.push_back(e.path());
  std::sort(files.rbegin(), files.rend());
  return files;
}

template <class Real>
RunSummary run_typed(const scene::Scene& scene, const RunOptions& options, std::uintmax_t first_output_bytes,
                     const std::function<void(const RunProgress&)>& on_progress) {
  RunSummary summary;
  summary.scene_file = scene.file;
  summary.precision = std::is_same_v<Real, float> ? "float" : "double";
  summary.out_dir = options.out_dir;
  summary.threads = parallel::thread_count();
  const std::uint64_t hash = scene::scene_hash(scene);

  auto built = build_simulation<Real>(scene);
  // Only now, so that a scene refused while its particles are built leaves no
  // empty output directory behind; nothing has been run yet.
  io::ensure_writable_directory(options.out_dir, first_output_bytes);
  Simulation<Real>& sim = built.sim;
  const sph::SphFluid<Real>* fluid = built.fluid;
  const gravity::GravityForce<Real>* self_gravity = built.self_gravity;
  sim.set_on_blow_up(options.on_blow_up);
  const bool adaptive = scene.adaptive_dt;
  // Adaptive runs log their step history per frame (run.hpp), after the solver's columns.
  const std::string step_columns = adaptive ? ",step,dt_min,dt_max,dt_next,limited_by" : "";
  std::optional<CsvLog> diagnostics;
  if (fluid)
    diagnostics.emplace(options.out_dir / "diagnostics.csv",
                        "time,kinetic_energy,potential_energy,momentum_x,momentum_y,momentum_z,"
                        "mean_density_error,max_density_error,mean_neighbours" + step_columns);
  else if (self_gravity)
    diagnostics.emplace(options.out_dir / "diagnostics.csv",
                        "time,kinetic_energy,potential_energy,total_energy,relative_energy_error,momentum_x,"
                        "momentum_y,momentum_z,angular_momentum_x,angular_momentum_y,angular_momentum_z,virial_ratio,"
                        "mean_nodes_visited" + step_columns);
  else if (adaptive)
    diagnostics.emplace(options.out_dir / "diagnostics.csv", "time" + step_columns);
  summary.particles = sim.particles().size();

  // Run state that must survive a restart, saved in every checkpoint.
  FrameWriter<Real> writer(scene, options.out_dir);
  double initial_energy = std::numeric_limits<double>::quiet_NaN();  // gravity runs: E at t = 0
  double energy_error = 0;
  double neighbor_sum = 0, nodes_sum = 0;  // per-evaluation means, summed for the summary
  std::uint64_t next_frame = 1, last_frame_step = 0, next_checkpoint = 1;
  // Adaptive steps: the smallest and largest step since the last frame.
  double frame_dt_min = std::numeric_limits<double>::infinity(), frame_dt_max = 0;
  double run_dt_min = std::numeric_limits<double>::infinity(), run_dt_max = 0;  // this invocation's, for the summary

  if (options.resume) {
    io::CheckpointValues values;
    std::optional<io::CheckpointHeader> header;
    for (const auto& file : checkpoints_in(options.out_dir)) {
      try {
        const auto h = io::read_checkpoint(file, sim.particles(), values);
        if (h.scene_hash != hash)
          throw io::IoError(fmt::format("{}: belongs to another scene (hash {:016x}, the scene's is {:016x})",
                                        file.string(), h.scene_hash, hash));
        header = h;
        summary.last_checkpoint = file;
        break;
      } catch (const io::IoError& e) {
        summary.warnings.push_back(fmt::format("skipping checkpoint: {}", e.what()));
      }
    }
    if (!header)
      throw io::IoError(fmt::format("{}: no valid checkpoint to resume from{}", checkpoint_dir(options.out_dir).string(),
                                    summary.warnings.empty() ? "" : " (" + summary.warnings.back() + ")"));
    if (adaptive) {
      // The controller's state; without it the resumed steps would differ.
      const double previous = value_of(values, "dt_previous", -1), floor = value_of(values, "dt_floor", -1);
      if (previous < 0 || floor < 0)
        throw io::IoError(fmt::format("{}: has no adaptive time-step state (dt_previous, dt_floor): not written by an "
                                      "adaptive run of this swirl", summary.last_checkpoint.string()));
      sim.resume(header->step, header->time, previous, floor);
      frame_dt_min = value_of(values, "frame_dt_min", frame_dt_min);
      frame_dt_max = value_of(values, "frame_dt_max", 0);
    } else {
      sim.resume(header->step);
    }
    summary.first_step = header->step;
    const auto frames = static_cast<std::size_t>(value_of(values, "frames", 0));
    writer.resume(frames);
    if (diagnostics) diagnostics->resume(frames);  // one row per frame
    next_frame = static_cast<std::uint64_t>(value_of(values, "next_frame", 1));
    last_frame_step = static_cast<std::uint64_t>(value_of(values, "last_frame_step", 0));
    next_checkpoint = static_cast<std::uint64_t>(value_of(values, "next_checkpoint", 1));
    initial_energy = value_of(values, "initial_energy", initial_energy);
    neighbor_sum = value_of(values, "neighbor_sum", 0);
    nodes_sum = value_of(values, "nodes_sum", 0);
  } else {
    io::write_file_atomic(options.out_dir / "scene.toml", scene.toml.empty() ? std::string("# built in code\n") : scene.toml);
  }

  std::uint64_t target = scene.total_steps();
  if (options.until) target = steps_until(*options.until, scene.dt);
  if (options.steps) target = summary.first_step + *options.steps;
  // Adaptive steps run to a time (landing on it exactly) unless a step count is asked for.
  const bool to_time = adaptive && !options.steps && (options.until || scene.end_time);
  const double end_time = to_time ? options.until.value_or(scene.end_time.value_or(0.0)) : 0.0;
  auto running = [&] { return to_time ? sim.time() < end_time : sim.step_count() < target; };
  // Progress of an adaptive run counts the steps still to go at the current step size.
  auto total_steps = [&] {
    if (!to_time) return target;
    const double left = std::max(0.0, (end_time - sim.time()) / sim.proposed_dt());
    return sim.step_count() + static_cast<std::uint64_t>(std::min(std::ceil(left), 1e18));
  };

  const auto started = std::chrono::steady_clock::now();
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(); };
  // Appends the step history (adaptive runs) and writes the row.
  auto add_diagnostics = [&](std::vector<double>& row) {
    if (!adaptive) return diagnostics->add(row);
    const bool stepped = frame_dt_max > 0;
    row.insert(row.end(), {double(sim.step_count()), stepped ? frame_dt_min : 0.0, frame_dt_max, sim.proposed_dt()});
    const auto& tight = sim.limits().tightest();
    const std::string_view by = sim.proposed_dt() < std::min(tight.dt, scene.dt) ? std::string_view("growth")
                                : tight.dt <= scene.dt                            ? tight.condition
                                                                                  : std::string_view("dt_max");
    diagnostics->add(row, by);
    frame_dt_min = std::numeric_limits<double>::infinity(), frame_dt_max = 0;
  };
  auto write_frame = [&] {
    ScopedPhase phase(sim.timers(), "output");
    const auto frame_file = writer.write(sim.particles(), sim.time());
    last_frame_step = sim.step_count();
    if (options.on_frame) options.on_frame(frame_file, sim.time());
    if (fluid) {
      const auto d = sph::fluid_diagnostics(sim.particles(), scene.gravity, scene.sph->rest_density, scene.block_size);
      auto row = std::vector<double>{sim.time(), d.kinetic_energy, d.potential_energy, d.momentum.x, d.momentum.y,
                                     d.momentum.z, d.mean_density_error, d.max_density_error, fluid->mean_neighbors()};
      add_diagnostics(row);
    } else if (self_gravity) {
      const auto d = gravity::diagnose(sim.particles(), scene.block_size);
      if (std::isnan(initial_energy)) initial_energy = d.total;
      energy_error = initial_energy != 0 ? (d.total - initial_energy) / std::abs(initial_energy) : 0.0;
      auto row = std::vector<double>{sim.time(), d.kinetic, d.potential, d.total, energy_error, d.momentum.x,
                                     d.momentum.y, d.momentum.z, d.angular_momentum.x, d.angular_momentum.y,
                                     d.angular_momentum.z, d.virial_ratio, self_gravity->stats().mean_nodes_visited};
      add_diagnostics(row);
    } else if (adaptive) {
      auto row = std::vector<double>{sim.time()};
      add_diagnostics(row);
    }
  };
  auto write_checkpoint = [&] {
    ScopedPhase phase(sim.timers(), "output");
    io::CheckpointValues values{{"frames", double(writer.frames())},
                                {"next_frame", double(next_frame)},
                                {"last_frame_step", double(last_frame_step)},
                                {"next_checkpoint", double(next_checkpoint)},
                                {"initial_energy", initial_energy},
                                {"neighbor_sum", neighbor_sum},
                                {"nodes_sum", nodes_sum}};
    if (adaptive)
      values.insert(values.end(), {{"dt_previous", sim.previous_dt()},
                                   {"dt_floor", sim.dt_floor()},
                                   {"frame_dt_min", frame_dt_min},
                                   {"frame_dt_max", frame_dt_max}});
    std::filesystem::create_directories(checkpoint_dir(options.out_dir));
    const auto file = checkpoint_dir(options.out_dir) / fmt::format("checkpoint_{:012d}.swc", sim.step_count());
    io::write_checkpoint(file, sim.particles(), {sizeof(Real), sim.particles().size(), hash, sim.step_count(), sim.time()},
                         values);
    summary.last_checkpoint = file;
    const auto files = checkpoints_in(options.out_dir);
    for (std::size_t k = std::max<std::size_t>(options.checkpoint_keep, 1); k < files.size(); ++k)
      std::filesystem::remove(files[k]);
  };

  // OnBlowUp::Warn: each kind of failed check is reported the 1st, 10th, 100th, ... time.
  std::vector<std::uint64_t> warned(4, 0);
  auto warn = [&](const GuardEvent& event) {
    const std::uint64_t n = ++warned[static_cast<std::size_t>(event.cause)];
    std::uint64_t decade = 1;
    while (decade * 10 <= n) decade *= 10;
    if (n != decade) return;
    const std::string text = n == 1 ? event.message : fmt::format("({} times so far) {}", n, event.message);
    if (options.on_warning) options.on_warning(text);
  };
  // Frame k is due at the first step with time ≥ k·interval; the slack keeps
  // k·interval that lands on a step (up to rounding) on that step. Checkpoints
  // by time follow the same rule. Adaptive steps land on k·interval exactly.
  const double interval = scene.output_interval;
  const double slack = 1e-9 * scene.dt;
  auto due = [&](double every, std::uint64_t k) { return sim.time() + slack >= static_cast<double>(k) * every; };
  auto after = [&](double every) { return static_cast<std::uint64_t>(std::floor((sim.time() + slack) / every)) + 1; };
  try {
    if (!options.resume) {
      sim.start();  // force models add their fields (density, potential) here
      write_frame();
    }
    summary.bytes_per_particle = bytes_per_particle(sim.particles());
    if (on_progress) on_progress({sim.step_count(), total_steps(), sim.time(), wall()});
    while (running()) {
      if (adaptive) {
        // Land exactly on the next output time and on the end time.
        std::optional<double> land;
        if (to_time) land = end_time;
        if (interval > 0) {
          const double frame_time = static_cast<double>(next_frame) * interval;
          if (!land || frame_time < *land) land = frame_time;
        }
        sim.step(land);
        frame_dt_min = std::min(frame_dt_min, sim.last_dt());
        frame_dt_max = std::max(frame_dt_max, sim.last_dt());
        run_dt_min = std::min(run_dt_min, sim.last_dt());
        run_dt_max = std::max(run_dt_max, sim.last_dt());
      } else {
        sim.step();
      }
      for (auto& event : sim.take_events()) warn(event);
      if (fluid) neighbor_sum += fluid->mean_neighbors();
      if (self_gravity) nodes_sum += self_gravity->stats().mean_nodes_visited;
      if (interval > 0 && due(interval, next_frame)) {
        write_frame();
        next_frame = after(interval);
      }
      bool checkpoint = options.checkpoint_every_steps && sim.step_count() % *options.checkpoint_every_steps == 0;
      if (options.checkpoint_every && due(*options.checkpoint_every, next_checkpoint)) {
        next_checkpoint = after(*options.checkpoint_every);
        checkpoint = true;
      }
      const bool stopping = options.stop && options.stop->load();
      if (checkpoint || stopping) write_checkpoint();
      if (on_progress) on_progress({sim.step_count(), total_steps(), sim.time(), wall()});
      if (stopping) {
        summary.interrupted = true;
        break;
      }
    }
    if (!summary.interrupted && last_frame_step != sim.step_count()) write_frame();
  } catch (const SimulationError& e) {
    summary.error = e.what();
    summary.blow_up = std::string(to_string(e.cause()));
  } catch (const io::IoError& e) {
    summary.error = fmt::format("writing output failed at step {}: {}", sim.step_count(), e.what());
  } catch (const std::filesystem::filesystem_error& e) {
    summary.error = fmt::format("writing output failed at step {}: {}", sim.step_count(), e.what());
  }

  for (std::size_t k = 0; k < warned.size(); ++k)
    if (warned[k] > 0)
      summary.warnings.push_back(fmt::format("{} steps failed the '{}' check (--on-blowup=warn)", warned[k],
                                             to_string(static_cast<BlowUpCause>(k))));
  summary.steps = sim.step_count() - summary.first_step;
  summary.sim_time = sim.time();
  summary.wall_seconds = wall();
  summary.steps_per_second = summary.wall_seconds > 0 ? static_cast<double>(summary.steps) / summary.wall_seconds : 0;
  summary.phases = sim.timers().phases();
  summary.frames = writer.frames();
  if (fluid && !sim.particles().empty())  // SPH search structures, lists and reorder scratch
    summary.bytes_per_particle += fluid->scratch_bytes() / sim.particles().size();
  const double evaluations = static_cast<double>(sim.step_count());
  if (fluid)
    summary.metrics.emplace_back("mean_neighbours", evaluations > 0 ? neighbor_sum / evaluations : fluid->mean_neighbors());
  if (adaptive && run_dt_max > 0) {  // landing steps included
    summary.metrics.emplace_back("smallest_dt", run_dt_min);
    summary.metrics.emplace_back("largest_dt", run_dt_max);
  }
  if (self_gravity) {
    summary.metrics.emplace_back("relative_energy_error", energy_error);  // at the last frame
    summary.metrics.emplace_back("mean_nodes_visited",
                                 evaluations > 0 ? nodes_sum / evaluations : self_gravity->stats().mean_nodes_visited);
    if (self_gravity->stats().tree_bytes > 0 && summary.particles > 0)
      summary.metrics.emplace_back("tree_bytes_per_particle",
                                   double(self_gravity->stats().tree_bytes) / double(summary.particles));
  }
  return summary;
}

// Memory and disk a scene needs, estimated before anything is allocated.
struct Footprint {
  double memory = 0;  // bytes: particle fields, solver scratch, neighbour lists
  double frame = 0;   // bytes of one .vtp frame
};

Footprint footprint(const scene::Scene& scene) {
  const double n = static_cast<double>(scene::count_particles(scene));
  const double real = scene.precision == scene::Precision::Float ? 4 : 8;
  // 16 reals and an id of fields; the scene's double copy while building; SPH
  // hash, sorted copies and ~40 neighbours of (index, r²) twice (block lists
  // and the CSR); tree nodes for gravity.
  double per_particle = 16 * real + 8 + 56;
  if (scene.sph) per_particle += 40 + 2 * 40 * (4 + real);
  if (scene.nbody) per_particle += 2 * 96;
  return {n * per_particle, n * (16 * real + 8 + 16) + 4096};
}

std::uint64_t memory_available() {
  const long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
  return pages > 0 && size > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(size) : 0;
}

}  // namespace

void check_memory(const scene::Scene& scene) {
  const Footprint f = footprint(scene);
  const std::uint64_t available = memory_available();
  if (available > 0 && f.memory > 0.9 * static_cast<double>(available))
    throw std::invalid_argument(fmt::format(
        "{}: {} particles need about {:.1f} GB of memory, more than the {:.1f} GB this machine has free",
        scene.file, scene::count_particles(scene), f.memory / 1e9, static_cast<double>(available) / 1e9));
}

RunSummary run_scene(const scene::Scene& scene, const RunOptions& options,
                     const std::function<void(const RunProgress&)>& on_progress) {
  check_memory(scene);
  if (options.threads > 0) parallel::set_thread_count(options.threads);
  const auto frame = static_cast<std::uintmax_t>(footprint(scene).frame);
  return scene.precision == scene::Precision::Float ? run_typed<float>(scene, options, frame, on_progress)
                                                    : run_typed<double>(scene, options, frame, on_progress);
}

}  // namespace swirl::sim
