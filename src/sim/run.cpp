#include "swirl/sim/run.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <memory>
#include <type_traits>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/dist/checkpoint_on_ranks.hpp"
#include "swirl/dist/gather_particles.hpp"
#include "swirl/dist/snapshot_on_ranks.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/checkpoint.hpp"
#include "swirl/io/csv.hpp"
#include "swirl/io/frame_names.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/run_folder.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/io/xdmf.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/scene/validate.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sim/footprint.hpp"
#include "swirl/sim/inlets_outlets.hpp"
#include "swirl/sim/mechanics.hpp"
#include "swirl/sim/observer.hpp"
#include "probe_log.hpp"

namespace swirl::sim {
namespace {

// Claims `path` in the run folder (rank 0's: it alone keeps the folder; null
// on the other ranks) and returns the claimed name on every rank, or throws
// rank 0's IoError on every rank: a write the ranks make together is started
// by every rank or by none.
std::filesystem::path claim_on_every_rank(io::RunFolder* folder, const dist::Communicator* ranks,
                                          const std::filesystem::path& path, bool sync = false) {
  std::string error;
  std::filesystem::path claimed = path;
  if (folder) {
    try {
      claimed = folder->claim(path, sync);
    } catch (const io::IoError& e) {
      error = e.what();
    }
  }
  if (ranks) error = ranks->first_text(error);
  if (!error.empty()) throw io::IoError(error);
  return claimed;
}

// ---------------------------------------------------------------------------
// Frames: particles_NNNNNN.vtp/.h5/.csv at the output interval, frame 0 at
// the start, the final state at the end; particles.pvd (VTK frames) and
// particles.xdmf (HDF5 snapshots) kept current. Boundary particles
// (core/particle_kind.hpp) go to their own series, boundary_NNNNNN.* with
// boundary.pvd and boundary.xdmf (io/frame_names.hpp): with every frame when
// some obstacle moves, else once, with the first frame (static ones never
// change: their positions, ψ-weighted masses, ρ0 and zero pressure).
template <class Real>
class FrameWriter final : public Observer<Real> {
 public:
  FrameWriter(const scene::Scene& scene, const RunOptions& options, io::RunFolder* folder)
      : formats_(scene.formats), dir_(options.out_dir), particles_(dir_, io::kParticleSeries, snapshot_info(scene).type),
        boundary_(dir_, io::kBoundarySeries, io::PartType::Boundary), snapshot_info_(snapshot_info(scene)),
        schedule_(scene.output_interval, scene.dt), on_frame_(options.on_frame), folder_(folder) {}

  std::string_view name() const override { return "frames"; }
  void on_start(Simulation<Real>& sim, bool resumed) override {
    if (!resumed) write(sim);
  }
  void on_step(Simulation<Real>& sim) override {
    if (!schedule_.due(sim.time())) return;
    write(sim);
    schedule_.acted(sim.time());
  }
  void on_finish(Simulation<Real>& sim) override {
    if (last_step_ != sim.step_count() || frames_ == 0) write(sim);
  }
  std::optional<double> next_time(const Simulation<Real>&) const override { return schedule_.next_time(); }

  void save_state(NamedValues& out) const override {
    out.emplace_back("frames.written", double(frames_));
    out.emplace_back("frames.next", double(schedule_.next_index()));
    out.emplace_back("frames.last_step", double(last_step_));
  }
  // Continues after the frames written before the checkpoint; later ones
  // (such as the final frame of a run that went on past it) are replaced.
  void load_state(const NamedValues& values) override {
    frames_ = static_cast<std::size_t>(find_value(values, "frames.written").value_or(0));
    schedule_.set_next_index(static_cast<std::uint64_t>(find_value(values, "frames.next").value_or(1)));
    last_step_ = static_cast<std::uint64_t>(find_value(values, "frames.last_step").value_or(0));
    particles_.resume(frames_, has(scene::OutputFormat::Hdf5));
    boundary_.resume(frames_, has(scene::OutputFormat::Hdf5));
  }
  std::size_t frames() const { return frames_; }

 private:
  // One series of frames (particles or boundary) and its listings.
  struct Series {
    Series(const std::filesystem::path& dir, std::string_view series, io::PartType part_type)
        : name(series), type(part_type), pvd(dir / fmt::format("{}.pvd", series)),
          xdmf(dir / fmt::format("{}.xdmf", series)) {}

    // The listings as they were with `frames` frames written (a resumed run):
    // the entries of frames before that index, from the .pvd and, for HDF5,
    // from the snapshots' headers.
    void resume(std::size_t frames, bool hdf5) {
      const std::filesystem::path dir = pvd.path().parent_path();
      const auto before = [&](const std::string& file) {
        const auto k = io::frame_index(file, name);
        return k && *k < frames;
      };
      written = 0;
      if (hdf5) {
        std::vector<io::XdmfEntry> entries;
        for (std::size_t f = 0; f < frames; ++f) {
          const std::string file = io::frame_file_name(name, f, ".h5");
          if (std::filesystem::exists(dir / file))
            entries.push_back({file, io::read_snapshot_layout(dir / file, int(type))});
        }
        written = std::max(written, entries.size());
        xdmf.set_entries(std::move(entries));
      }
      if (!std::filesystem::exists(pvd.path())) return;
      auto entries = io::read_pvd(pvd.path());
      std::erase_if(entries, [&](const io::PvdEntry& e) { return !before(e.file); });
      written = std::max(written, entries.size());
      pvd.set_entries(std::move(entries));
    }

    std::string_view name;
    io::PartType type;  // in its HDF5 snapshots
    io::PvdSeries pvd;
    io::XdmfSeries xdmf;
    std::size_t written = 0;  // frames of this series so far
  };

  // Writes frame frames_. On several ranks HDF5 snapshots are written by every
  // rank from its own particles (parallel HDF5: dist/snapshot_on_ranks.hpp), while the
  // VTK and CSV files are rank 0's, from the gathered whole set (gathered
  // only for them).
  void write(Simulation<Real>& sim) {
    ScopedPhase phase(sim.timers(), "output");
    const dist::Communicator* ranks = sim.ranks() ? &sim.ranks()->comm() : nullptr;
    const bool gather = !ranks || std::any_of(formats_.begin(), formats_.end(), [](scene::OutputFormat f) {
      return f != scene::OutputFormat::Hdf5;
    });
    Sources sources;
    if (gather) {
      sources.whole = &sim.whole_particles();  // collective on ranks; empty on ranks other than 0
      sources.whole_split = split_by_kind(*sources.whole);
    }
    sources.own = ranks ? &sim.particles() : sources.whole;
    if (ranks) sources.own_split = split_by_kind(sim.particles());
    std::uint64_t boundary = sources.own_kinds().boundary.size();
    if (ranks) boundary = ranks->sum(boundary);

    std::filesystem::path first;
    if (boundary == 0) {
      first = write_frame(sim, ranks, particles_, sources, nullptr);
    } else {
      first = write_frame(sim, ranks, particles_, sources, &KindSplit::rest);
      const auto* moving = sim.moving_boundaries();
      if (boundary_.written == 0 || (moving && !moving->empty()))
        write_frame(sim, ranks, boundary_, sources, &KindSplit::boundary);
    }
    ++frames_;
    last_step_ = sim.step_count();
    if (!folder_) return;  // a rank other than 0
    io::RunFolder& folder = *folder_;
    if (on_frame_) on_frame_(first, sim.time(), [&folder](const std::filesystem::path& p) { return folder.claim(p); });
  }

  // The particles a frame is written from: this rank's own (its part of an
  // HDF5 snapshot) and the whole set (rank 0's VTK and CSV files; null when
  // no format needs it), each with its split by kind. One rank: both the same.
  struct Sources {
    const ParticleSet<Real>* own = nullptr;
    const ParticleSet<Real>* whole = nullptr;
    KindSplit own_split, whole_split;  // own_split: on ranks only
    const KindSplit& own_kinds() const { return own == whole ? whole_split : own_split; }
  };

  // Writes frame frames_ of `series` in every format, of the particles of the
  // kind `kind` selects (every particle when null); returns rank 0's first
  // format's file. Collective on ranks.
  std::filesystem::path write_frame(const Simulation<Real>& sim, const dist::Communicator* ranks, Series& series,
                                    const Sources& from, std::vector<std::size_t> KindSplit::*kind) {
    const double time = sim.time();
    // The rows of a source's set this series holds (nullopt: all of them).
    const auto rows = [&](const KindSplit& split) -> io::ParticleRows {
      if (!kind) return std::nullopt;
      return std::span<const std::size_t>(split.*kind);
    };
    std::filesystem::path first;
    std::optional<ParticleSet<Real>> subset;  // the VTK and CSV files' copy of this series' particles
    for (auto format : formats_) {
      std::filesystem::path file;
      if (format == scene::OutputFormat::Hdf5) {
        const std::string name = io::frame_file_name(series.name, frames_, ".h5");
        file = claim_on_every_rank(folder_, ranks, dir_ / name);
        io::SnapshotInfo info = snapshot_info_;
        info.time = time;
        info.type = series.type;
        const io::ParticleRows own_rows = rows(from.own_kinds());
        io::SnapshotLayout layout = ranks ? dist::write_snapshot_on_ranks(*ranks, file, *from.own, info, own_rows)
                                          : io::write_snapshot(file, *from.own, info, own_rows);
        if (folder_) {
          folder_->claim(series.xdmf.path());
          series.xdmf.add(name, std::move(layout));
        }
      } else if (folder_) {  // rank 0, from the whole set (this series' particles copied once)
        if (kind && !subset) subset = from.whole->subset(from.whole_split.*kind);
        const ParticleSet<Real>& set = kind ? *subset : *from.whole;
        if (format == scene::OutputFormat::Vtp) {
          const std::string name = io::frame_file_name(series.name, frames_, ".vtp");
          file = folder_->claim(dir_ / name);
          io::write_vtp(file, set, time);
          folder_->claim(series.pvd.path());
          series.pvd.add(time, name);
        } else {
          file = folder_->claim(dir_ / io::frame_file_name(series.name, frames_, ".csv"));
          io::write_csv(file, set, time);
        }
      }
      if (first.empty()) first = file;
    }
    ++series.written;
    return first;
  }

  bool has(scene::OutputFormat format) const {
    return std::find(formats_.begin(), formats_.end(), format) != formats_.end();
  }
  // What every snapshot of this scene says beside its particles (the time is the frame's).
  static io::SnapshotInfo snapshot_info(const scene::Scene& scene) {
    io::SnapshotInfo info;
    info.type = scene.sph ? io::PartType::Gas : io::PartType::Collisionless;
    if (scene.walls) {
      const Vec3d e = scene.box.extent();
      info.box_size = std::max({e.x, e.y, e.z});
    }
    info.si_units = scene.units == scene::Units::SI;
    info.gravitational_constant = scene.gravitational_constant;
    return info;
  }

  std::vector<scene::OutputFormat> formats_;
  std::filesystem::path dir_;
  Series particles_, boundary_;
  io::SnapshotInfo snapshot_info_;
  IntervalSchedule schedule_;
  FrameHook on_frame_;
  io::RunFolder* folder_;  // null on ranks other than 0
  std::size_t frames_ = 0;
  std::uint64_t last_step_ = 0;
};

// ---------------------------------------------------------------------------
// diagnostics.csv: one row per output time (the frames' schedule), rewritten
// atomically after each row. The run's mechanics first — kinetic, potential
// (every solver's) and total energy, the relative energy error when every
// solver conserves energy, momentum and angular momentum (about the origin) —
// then each solver's own columns, then, for adaptive steps, the step history
// since the previous row (steps so far, smallest and largest step, the step
// proposed next and the condition that sets it).
template <class Real>
class DiagnosticsLog final : public Observer<Real> {
 public:
  DiagnosticsLog(const scene::Scene& scene, const RunOptions& options, const Simulation<Real>& sim,
                 io::RunFolder* folder)
      : path_(options.out_dir / "diagnostics.csv"), schedule_(scene.output_interval, scene.dt),
        adaptive_(scene.adaptive_dt), dt_max_(scene.dt), block_size_(scene.block_size),
        max_energy_error_(scene.max_energy_error), folder_(folder) {
    // Walls that keep less than all of the normal speed take energy out.
    conservative_ = std::all_of(sim.solvers().begin(), sim.solvers().end(),
                                [](const auto& s) { return s->conserves_energy(); }) &&
                    (!scene.walls || scene.restitution == 1);
    std::string header = "time,kinetic_energy,potential_energy,total_energy";
    if (conservative_) header += ",relative_energy_error";
    header += ",momentum_x,momentum_y,momentum_z,angular_momentum_x,angular_momentum_y,angular_momentum_z";
    for (const auto& s : sim.solvers())
      for (const auto& c : s->diagnostic_columns()) header += "," + c;
    for (const auto& c : sim.stepper().diagnostic_columns()) header += "," + c;
    if (adaptive_) header += ",step,dt_min,dt_max,dt_next,limited_by";
    text_ = header + "\n";
  }

  std::string_view name() const override { return "diagnostics"; }
  void on_start(Simulation<Real>& sim, bool resumed) override {
    if (!resumed) add_row(sim);
  }
  void on_step(Simulation<Real>& sim) override {
    frame_dt_min_ = std::min(frame_dt_min_, sim.last_dt());
    frame_dt_max_ = std::max(frame_dt_max_, sim.last_dt());
    if (!schedule_.due(sim.time())) return;
    add_row(sim);
    schedule_.acted(sim.time());
  }
  void on_finish(Simulation<Real>& sim) override {
    if (last_step_ != sim.step_count() || rows_ == 0) add_row(sim);
  }
  std::optional<double> next_time(const Simulation<Real>&) const override { return schedule_.next_time(); }

  void save_state(NamedValues& out) const override {
    out.insert(out.end(), {{"diagnostics.rows", double(rows_)},
                           {"diagnostics.next", double(schedule_.next_index())},
                           {"diagnostics.last_step", double(last_step_)},
                           {"diagnostics.initial_energy", initial_energy_},
                           {"diagnostics.frame_dt_min", frame_dt_min_},
                           {"diagnostics.frame_dt_max", frame_dt_max_}});
  }
  // Continues the log, keeping the rows written before the checkpoint.
  void load_state(const NamedValues& values) override {
    rows_ = static_cast<std::size_t>(find_value(values, "diagnostics.rows").value_or(0));
    schedule_.set_next_index(static_cast<std::uint64_t>(find_value(values, "diagnostics.next").value_or(1)));
    last_step_ = static_cast<std::uint64_t>(find_value(values, "diagnostics.last_step").value_or(0));
    initial_energy_ = find_value(values, "diagnostics.initial_energy").value_or(initial_energy_);
    frame_dt_min_ = find_value(values, "diagnostics.frame_dt_min").value_or(frame_dt_min_);
    frame_dt_max_ = find_value(values, "diagnostics.frame_dt_max").value_or(0);
    if (!std::filesystem::exists(path_)) return;
    std::istringstream in(io::read_text_file(path_));
    std::string line;
    std::getline(in, line);  // the header, as this version writes it
    for (std::size_t k = 0; k < rows_ && std::getline(in, line); ++k) text_ += line + "\n";
  }

  // The relative energy error at the last row (conservative runs), for the summary.
  std::optional<double> energy_error() const {
    if (!conservative_ || rows_ == 0) return std::nullopt;
    return energy_error_;
  }

 private:
  void add_row(Simulation<Real>& sim) {
    ScopedPhase phase(sim.timers(), "output");
    // Every rank's own particles, reduced in the one-rank block order
    // (dist::BlockFold): collective on ranks, no gather.
    const auto& p = sim.particles();
    dist::BlockFold fold = dist::BlockFold::one_rank(block_size_);
    if (const auto* ranks = sim.ranks()) fold.ranks = &ranks->comm(), fold.first = ranks->first_global_index();
    const Mechanics m = mechanics(p, fold);
    const double potential = potential_energy(sim, p, fold);
    const auto columns = diagnostic_values(sim, p, fold);
    if (!folder_) {  // a rank other than 0: rank 0 writes, and checks the energy
      ++rows_;
      last_step_ = sim.step_count();
      return;
    }
    const double total = m.kinetic + potential;
    std::vector<double> row{sim.time(), m.kinetic, potential, total};
    if (conservative_) {
      if (std::isnan(initial_energy_)) initial_energy_ = total;
      energy_error_ = initial_energy_ != 0 ? (total - initial_energy_) / std::abs(initial_energy_) : 0.0;
      row.push_back(energy_error_);
    }
    row.insert(row.end(), {m.momentum[0], m.momentum[1], m.momentum[2], m.angular[0], m.angular[1], m.angular[2]});
    for (const auto& column : columns) row.push_back(column.second);
    for (std::size_t k = 0; k < row.size(); ++k) text_ += fmt::format("{}{:.9g}", k ? "," : "", row[k]);
    if (adaptive_) {
      const bool stepped = frame_dt_max_ > 0;
      text_ += fmt::format(",{:.9g},{:.9g},{:.9g},{:.9g},{}", double(sim.step_count()), stepped ? frame_dt_min_ : 0.0,
                           frame_dt_max_, sim.proposed_dt(), limited_by(sim));
      frame_dt_min_ = std::numeric_limits<double>::infinity(), frame_dt_max_ = 0;
    }
    text_ += "\n";
    io::write_file_atomic(folder_->claim(path_), text_);
    ++rows_;
    last_step_ = sim.step_count();
    // Checked once the row is written: the log shows the error that stopped the run.
    if (conservative_ && max_energy_error_ > 0 && !(std::abs(energy_error_) <= max_energy_error_))
      sim.fail_check(BlowUpCause::EnergyDrift,
                     fmt::format("the relative energy error is {:.3g} (E = {:.6g}, E0 = {:.6g}), beyond "
                                 "simulation.max_energy_error = {:.3g}: the forces or the steps no longer resolve the "
                                 "motion (a close encounter, or a step too long)",
                                 energy_error_, total, initial_energy_, max_energy_error_));
  }

  // What sets the next adaptive step: a condition, dt_max, or the growth cap.
  std::string_view limited_by(const Simulation<Real>& sim) const {
    const auto& tight = sim.tightest();
    if (sim.proposed_dt() < std::min(tight.dt, dt_max_)) return "growth";
    return tight.dt <= dt_max_ ? tight.condition : std::string_view("dt_max");
  }

  std::filesystem::path path_;
  IntervalSchedule schedule_;
  bool adaptive_;
  double dt_max_;
  std::size_t block_size_;
  double max_energy_error_;
  io::RunFolder* folder_;  // null on ranks other than 0
  bool conservative_ = true;
  std::string text_;
  std::size_t rows_ = 0;
  std::uint64_t last_step_ = 0;
  double initial_energy_ = std::numeric_limits<double>::quiet_NaN();
  double energy_error_ = 0;
  double frame_dt_min_ = std::numeric_limits<double>::infinity(), frame_dt_max_ = 0;
};

// ---------------------------------------------------------------------------
// Checkpoints in out_dir/checkpoints/: every N steps and/or every T of
// simulated time, and when the run is asked to stop. Each holds the particle
// fields, the simulation's clock and state, and every observer's state.
std::filesystem::path checkpoint_dir(const std::filesystem::path& out) { return out / "checkpoints"; }

// This run's checkpoint files (the run folder's manifest lists them; a user's
// or another run's .swc is never chosen or pruned), newest (highest step) first.
std::vector<std::filesystem::path> checkpoints_in(const io::RunFolder& folder) {
  std::vector<std::filesystem::path> files;
  const auto dir = checkpoint_dir(folder.dir());
  if (!std::filesystem::is_directory(dir)) return files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".swc" && folder.owns(e.path())) files.push_back(e.path());
  std::sort(files.rbegin(), files.rend());
  return files;
}

void save_clock(const SimulationClock& c, NamedValues& out) {
  out.insert(out.end(), {{"clock.previous_dt", c.previous_dt}, {"clock.dt_floor", c.dt_floor}});
}

template <class Real>
class Checkpointer final : public Observer<Real> {
 public:
  using Collect = std::function<void(NamedValues&)>;
  Checkpointer(const scene::Scene& scene, const RunOptions& options, std::uint64_t scene_hash, Collect collect,
               io::RunFolder* folder)
      : options_(options), schedule_(options.checkpoint_every.value_or(0), scene.dt), hash_(scene_hash),
        collect_(std::move(collect)), folder_(folder) {}

  std::string_view name() const override { return "checkpoints"; }
  void on_step(Simulation<Real>& sim) override {
    bool now = options_.checkpoint_every_steps && sim.step_count() % *options_.checkpoint_every_steps == 0;
    if (schedule_.due(sim.time())) {
      schedule_.acted(sim.time());
      now = true;
    }
    if (now) write(sim);
  }
  void save_state(NamedValues& out) const override {
    out.emplace_back("checkpoints.next", double(schedule_.next_index()));
  }
  void load_state(const NamedValues& values) override {
    schedule_.set_next_index(static_cast<std::uint64_t>(find_value(values, "checkpoints.next").value_or(1)));
  }

  // Writes one now (the run calls it when asked to stop), unless one was written at this step.
  void write(Simulation<Real>& sim) {
    if (!last_.empty() && last_step_ == sim.step_count()) return;
    last_step_ = sim.step_count();
    ScopedPhase phase(sim.timers(), "output");
    NamedValues values;
    collect_(values);
    const auto path = checkpoint_dir(options_.out_dir) / fmt::format("checkpoint_{:012d}.swc", sim.step_count());
    last_ = path;
    const dist::Communicator* ranks = sim.ranks() ? &sim.ranks()->comm() : nullptr;
    // Claimed (and the manifest synced) before it is written: a resume after a
    // power cut still knows it is this run's.
    const auto file = claim_on_every_rank(folder_, ranks, path, /*sync=*/true);
    const io::CheckpointHeader header{sizeof(Real), sim.particles().size(), hash_, sim.step_count(), sim.time()};
    if (ranks)  // rank 0 writes while the ranks hand it one field at a time
      dist::write_checkpoint_on_ranks(*ranks, file, sim.particles(), header, values);
    else
      io::write_checkpoint(file, sim.particles(), header, values);
    if (!folder_) return;  // a rank other than 0
    last_ = file;
    const auto files = checkpoints_in(*folder_);
    for (std::size_t k = std::max<std::size_t>(options_.checkpoint_keep, 1); k < files.size(); ++k)
      folder_->remove(files[k]);
  }
  const std::filesystem::path& last() const { return last_; }

 private:
  const RunOptions& options_;
  IntervalSchedule schedule_;
  std::uint64_t hash_;
  Collect collect_;
  io::RunFolder* folder_;  // null on ranks other than 0
  std::filesystem::path last_;
  std::uint64_t last_step_ = 0;
};

// ---------------------------------------------------------------------------
// OnBlowUp::Warn: each kind of failed check reported the 1st, 10th, 100th, ... time.
template <class Real>
class GuardReporter final : public Observer<Real> {
 public:
  explicit GuardReporter(std::function<void(const std::string&)> on_warning) : on_warning_(std::move(on_warning)) {}
  std::string_view name() const override { return "guard"; }
  void on_step(Simulation<Real>& sim) override {
    for (const GuardEvent& event : sim.take_events()) {
      const std::uint64_t n = ++counts_[static_cast<std::size_t>(event.cause)];
      std::uint64_t decade = 1;
      while (decade * 10 <= n) decade *= 10;
      if (n != decade || !on_warning_) continue;
      on_warning_(n == 1 ? event.message : fmt::format("({} times so far) {}", n, event.message));
    }
  }
  // The diagnostics' last row (its energy check) comes after the last step.
  void on_finish(Simulation<Real>& sim) override { on_step(sim); }
  // One line per kind of check that failed.
  std::vector<std::string> failed_checks() const {
    std::vector<std::string> out;
    for (std::size_t k = 0; k < counts_.size(); ++k)
      if (counts_[k] > 0)
        out.push_back(fmt::format("{} {} failed the '{}' check", counts_[k], counts_[k] == 1 ? "step" : "steps",
                                  to_string(static_cast<BlowUpCause>(k))));
    return out;
  }

 private:
  std::function<void(const std::string&)> on_warning_;
  std::array<std::uint64_t, kBlowUpCauses> counts_{};
};

// ---------------------------------------------------------------------------
// The progress callback, and this invocation's smallest and largest step.
template <class Real>
class Progress final : public Observer<Real> {
 public:
  using Callback = std::function<void(const RunProgress&)>;
  using Total = std::function<std::uint64_t()>;
  Progress(Callback callback, Total total, std::string_view time_unit)
      : callback_(std::move(callback)), total_(std::move(total)), time_unit_(time_unit) {}
  std::string_view name() const override { return "progress"; }
  // The wall clock runs from construction: before start() and frame 0, as the phase timers do.
  void on_start(Simulation<Real>& sim, bool) override {
    first_step_ = sim.step_count();
    report(sim);
  }
  void on_step(Simulation<Real>& sim) override {
    dt_min_ = std::min(dt_min_, sim.last_dt());
    dt_max_ = std::max(dt_max_, sim.last_dt());
    report(sim);
  }
  double wall() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count(); }
  double dt_min() const { return dt_min_; }
  double dt_max() const { return dt_max_; }

 private:
  void report(const Simulation<Real>& sim) const {
    if (callback_) callback_({sim.step_count(), first_step_, total_(), sim.time(), wall(), time_unit_});
  }
  Callback callback_;
  Total total_;
  std::string_view time_unit_;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::uint64_t first_step_ = 0;
  double dt_min_ = std::numeric_limits<double>::infinity(), dt_max_ = 0;
};

// ---------------------------------------------------------------------------
template <class Real>
std::size_t bytes_per_particle(const Simulation<Real>& sim) {
  const auto& p = sim.particles();
  std::size_t bytes = sizeof(std::uint64_t);  // id
  for (const auto& f : p.fields()) bytes += static_cast<std::size_t>(f.components) * sizeof(Real);
  bytes += p.int_field_count() * sizeof(typename ParticleSet<Real>::int_type);
  if (p.empty()) return bytes;
  std::size_t scratch = sim.ranks() ? sim.ranks()->bytes() : sim.order().bytes();  // on ranks order() is unused
  for (const auto& s : sim.solvers()) scratch += s->scratch_bytes();
  return bytes + scratch / p.size();
}

// Steps from t = 0 to time t (the same rounding as Scene::total_steps).
std::uint64_t steps_until(double t, double dt) {
  return static_cast<std::uint64_t>(std::max(0.0, std::ceil(t / dt - 1e-9)));
}

// Where a run ends: a step count, or (adaptive steps) a time landed on
// exactly. Checkpoints carry it ("run.end_step" / "run.end_time"), so a
// resume without --steps or --until ends where the first invocation would
// have (its --steps or --until included).
struct RunEnd {
  bool to_time = false;
  std::uint64_t step = 0;  // !to_time
  double time = 0;         // to_time

  // From the flags (--steps: that many more from `from_step`), else what the
  // checkpoint remembers, else the scene.
  static RunEnd choose(const scene::Scene& scene, const RunOptions& options, std::uint64_t from_step, double from_time,
                       const NamedValues* saved) {
    RunEnd e;
    if (options.steps) {
      if (*options.steps > kMaxSteps - std::min(from_step, kMaxSteps))
        throw std::invalid_argument(fmt::format("--steps {}: from step {} that passes the 2^53 steps a run can count",
                                                *options.steps, from_step));
      e.step = from_step + *options.steps;
      return e;
    }
    if (options.until) {
      if (!(*options.until > from_time))
        throw std::invalid_argument(fmt::format("--until {}: the run is already at t = {:.6g}; give a later time",
                                                *options.until, from_time));
      return at_time(scene, *options.until);
    }
    if (saved) {
      if (const auto step = find_value(*saved, "run.end_step")) {
        e.step = static_cast<std::uint64_t>(*step);
        return e;
      }
      if (const auto time = find_value(*saved, "run.end_time")) return at_time(scene, *time);
    }
    if (scene.adaptive_dt && scene.end_time) return at_time(scene, *scene.end_time);
    e.step = scene.total_steps();
    return e;
  }
  static RunEnd at_time(const scene::Scene& scene, double t) {
    RunEnd e;
    if (scene.adaptive_dt) {
      e.to_time = true, e.time = t;
    } else {
      e.step = steps_until(t, scene.dt);
    }
    return e;
  }
  void save(NamedValues& out) const {
    out.emplace_back(to_time ? "run.end_time" : "run.end_step", to_time ? time : double(step));
  }
  std::string describe() const {
    return to_time ? fmt::format("t = {:.6g}", time) : fmt::format("step {}", step);
  }
};

// Reads the newest valid checkpoint of this scene into sim and returns its
// header and values; warnings name the files skipped.
template <class Real>
std::pair<io::CheckpointHeader, NamedValues> read_newest_checkpoint(Simulation<Real>& sim, const io::RunFolder& folder,
                                                                    std::uint64_t hash, RunSummary& summary) {
  for (const auto& file : checkpoints_in(folder)) {
    try {
      NamedValues values;
      const auto h = io::read_checkpoint(file, sim.particles(), values);
      if (h.scene_hash != hash)
        throw io::IoError(fmt::format("{}: belongs to another scene (hash {:016x}, the scene's is {:016x}), or to "
                                      "this one under a default that has changed since (docs/scenes.md lists "
                                      "the defaults; a key written out keeps its value)",
                                      file.string(), h.scene_hash, hash));
      summary.last_checkpoint = file;
      return {h, std::move(values)};
    } catch (const io::IoError& e) {
      summary.warnings.push_back(fmt::format("skipping checkpoint: {}", e.what()));
    }
  }
  throw io::IoError(fmt::format("{}: no valid checkpoint to resume from{}", checkpoint_dir(folder.dir()).string(),
                                summary.warnings.empty() ? "" : " (" + summary.warnings.back() + ")"));
}

// Rank 0's checkpoint header (step, time) and values on every rank, bit for bit.
std::pair<io::CheckpointHeader, NamedValues> share_checkpoint_values(
    const dist::Communicator& comm, const std::pair<io::CheckpointHeader, NamedValues>& mine) {
  // Lines "name<TAB>bits" (hex, exact), after one for the header.
  std::string text;
  if (comm.is_root()) {
    text = fmt::format("{:x}\t{:x}\n", mine.first.step, std::bit_cast<std::uint64_t>(mine.first.time));
    for (const auto& [name, value] : mine.second) text += fmt::format("{}\t{:x}\n", name, std::bit_cast<std::uint64_t>(value));
  }
  text = comm.first_text(text);
  if (comm.is_root()) return mine;
  std::pair<io::CheckpointHeader, NamedValues> out;
  out.first = mine.first;
  std::size_t at = 0;
  bool header = true;
  while (at < text.size()) {
    const std::size_t tab = text.find('\t', at), end = text.find('\n', at);
    const std::string name = text.substr(at, tab - at);
    const std::uint64_t bits = std::stoull(text.substr(tab + 1, end - tab - 1), nullptr, 16);
    if (header) {
      out.first.step = std::stoull(name, nullptr, 16);
      out.first.time = std::bit_cast<double>(bits);
      header = false;
    } else {
      out.second.emplace_back(name, std::bit_cast<double>(bits));
    }
    at = end + 1;
  }
  return out;
}

// Each rank's figures (the same names on every rank) as "<name>_mean" and
// "<name>_max" over the ranks. Collective.
void add_over_ranks(const dist::Communicator& comm, const NamedValues& mine, NamedValues& out) {
  std::vector<double> values;
  for (const auto& [name, value] : mine) values.push_back(value);
  const std::vector<dist::Bytes> all = comm.all_gather(dist::to_bytes(std::span<const double>(values)));
  for (std::size_t k = 0; k < mine.size(); ++k) {
    double sum = 0, largest = -std::numeric_limits<double>::infinity();
    for (const dist::Bytes& b : all) {
      std::vector<double> theirs;
      dist::append_values(b, theirs, "rank metrics");
      if (theirs.size() != values.size()) throw std::logic_error("rank metrics: the ranks report different figures");
      sum += theirs[k];
      largest = std::max(largest, theirs[k]);
    }
    out.emplace_back(mine[k].first + "_mean", sum / double(all.size()));
    out.emplace_back(mine[k].first + "_max", largest);
  }
}

// What stopped a stage of the loop: a blow-up, a failed write; empty: nothing.
struct Failure {
  std::string error;
  std::string blow_up;
};

// On several ranks every rank must leave the loop at the same step: a failure
// on one rank (rank 0's write, its energy check) is made every rank's, with
// the words of the lowest rank that failed.
Failure agree(const dist::Communicator& comm, const Failure& mine) {
  if (!comm.distributed()) return mine;
  const std::string all = comm.first_text(mine.error.empty() ? std::string() : mine.blow_up + '\n' + mine.error);
  if (all.empty()) return {};
  const auto cut = all.find('\n');
  return {all.substr(cut + 1), all.substr(0, cut)};
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

  const dist::Communicator& comm = options.ranks ? *options.ranks : dist::Communicator::world();
  const bool on_ranks = options.ranks && options.ranks->distributed();
  const bool root = !on_ranks || comm.is_root();
  if (on_ranks) {
    if (const std::string no = distributed_support(scene); !no.empty())
      throw std::invalid_argument(fmt::format("{}: {} does not run on several MPI ranks yet ({} ranks were started); "
                                              "run it on one (docs/design/mpi.md says what is distributed so far)",
                                              scene.file, no, comm.size()));
    if (options.extend_float || options.extend_double)
      throw std::invalid_argument("solvers and observers added from Python do not run on several MPI ranks");
  }
  // On several ranks rank 0 alone builds the particles (the peak memory is one
  // set, not one per rank) and sends each rank its share at start; its
  // refusal of the scene is every rank's.
  ParticleSet<Real> built;
  if (root) {
    if (!on_ranks) {
      built = scene::make_particles<Real>(scene);
    } else {
      std::string refused;
      try {
        built = scene::make_particles<Real>(scene);
      } catch (const std::exception& e) {  // a scene's or a file's refusal: bad input on every rank
        refused = e.what();
      }
      if (!comm.first_text(refused).empty()) throw std::invalid_argument(refused);
    }
  } else if (const std::string refused = comm.first_text({}); !refused.empty()) {
    throw std::invalid_argument(refused);
  }
  const std::uint64_t particle_count = on_ranks ? comm.sum(std::uint64_t(built.size())) : built.size();
  if (on_ranks) {
    dist::share_layout_from_root(comm, built);
    if (particle_count < static_cast<std::uint64_t>(comm.size()))
      throw std::invalid_argument(fmt::format("{}: {} particles on {} MPI ranks: every rank needs at least one "
                                              "particle; run on at most {} rank{}",
                                              scene.file, particle_count, comm.size(),
                                              std::max<std::uint64_t>(particle_count, 1), particle_count > 1 ? "s" : ""));
  }
  Simulation<Real> sim = build_simulation<Real>(scene, std::move(built));
  if (on_ranks) sim.distribute(comm, /*whole_on_root=*/true);
  std::vector<std::shared_ptr<Observer<Real>>> added;
  if constexpr (std::is_same_v<Real, float>) {
    if (options.extend_float) added = options.extend_float(sim);
  } else {
    if (options.extend_double) added = options.extend_double(sim);
  }
  // Only now, so that a scene refused while its particles are built leaves no
  // empty output directory behind; nothing has been run yet.
  // On several ranks only rank 0 writes, so only rank 0 takes the folder.
  // Set-up that rank 0 does alone: on several ranks its failure (a folder
  // that cannot be written or holds another run, no checkpoint to resume
  // from) is made every rank's, as bad input (std::invalid_argument).
  auto on_root = [&](auto&& body) {
    if (!on_ranks) return body();
    Failure failure;
    if (root) {
      try {
        body();
      } catch (const std::exception& e) {
        failure.error = e.what();
      }
    }
    failure = agree(comm, failure);
    if (!failure.error.empty()) throw std::invalid_argument(failure.error);
  };
  std::optional<io::RunFolder> folder_of_run;
  on_root([&] {
    io::ensure_writable_directory(options.out_dir, first_output_bytes);
    // The folder is this run's for as long as it runs (a lock), and it writes
    // only files that are its own (io/run_folder.hpp).
    folder_of_run.emplace(options.out_dir,
                          options.resume      ? io::RunFolderMode::Resume
                          : options.overwrite ? io::RunFolderMode::Overwrite
                                              : io::RunFolderMode::Fresh,
                          fmt::format("{} {:016x}", scene.file, hash));
  });
  io::RunFolder* folder = folder_of_run ? &*folder_of_run : nullptr;
  // Valid but likely to hurt (zero softening): said before the first step.
  for (const std::string& w : scene::advisories(scene)) {
    if (!root) break;
    if (options.on_warning) options.on_warning(w);
    else summary.warnings.push_back(w);
  }
  sim.set_on_blow_up(options.on_blow_up);
  sim.prepare();  // every field declared, so a checkpoint's fields meet their uses
  summary.particles = particle_count;

  // Where the run ends (RunEnd): decided once the clock is known (below).
  const bool adaptive = scene.adaptive_dt;
  RunEnd end;
  auto total_steps = [&]() -> std::uint64_t {
    if (!end.to_time) return std::max(end.step, sim.step_count());
    // An estimate: the steps still to go at the current step size.
    const double left = std::max(0.0, (end.time - sim.time()) / sim.proposed_dt());
    return sim.step_count() + static_cast<std::uint64_t>(std::min(std::ceil(left), 1e18));
  };

  // The observers, in the order they act after a step.
  auto frames = std::make_unique<FrameWriter<Real>>(scene, options, folder);
  auto diagnostics = std::make_unique<DiagnosticsLog<Real>>(scene, options, sim, folder);
  auto guard = std::make_unique<GuardReporter<Real>>(options.on_warning);
  const std::string_view time_unit = scene.units == scene::Units::SI ? "s" : "";  // a literal: outlives the run
  summary.time_unit = std::string(time_unit);
  auto progress = std::make_unique<Progress<Real>>(on_progress, total_steps, time_unit);
  std::unique_ptr<ProbeLog<Real>> probes;
  if (scene.has_probe_output()) probes = std::make_unique<ProbeLog<Real>>(scene, options, folder);
  // Inlets and outlets act first: frames, diagnostics and checkpoints see the changed set.
  std::unique_ptr<InletsAndOutlets<Real>> inlets;
  if (scene.has_inlets_or_outlets()) inlets = std::make_unique<InletsAndOutlets<Real>>(scene);
  std::vector<Observer<Real>*> observers;
  if (inlets) observers.push_back(inlets.get());
  observers.push_back(frames.get());
  observers.push_back(diagnostics.get());
  if (probes) observers.push_back(probes.get());
  observers.push_back(guard.get());
  for (const auto& o : added) observers.push_back(o.get());
  auto collect = [&](NamedValues& values) {
    end.save(values);
    save_clock(sim.clock(), values);
    sim.save_state(values);
    for (const Observer<Real>* o : observers) o->save_state(values);
  };
  auto checkpoints = std::make_unique<Checkpointer<Real>>(scene, options, hash, collect, folder);
  observers.push_back(checkpoints.get());
  observers.push_back(progress.get());

  if (options.resume) {
    std::pair<io::CheckpointHeader, NamedValues> read;
    on_root([&] { read = read_newest_checkpoint(sim, *folder, hash, summary); });
    if (on_ranks) {
      // Rank 0 read the checkpoint whole; the others get its fields, its clock
      // and the states (resume() sends each rank its particles).
      summary.last_checkpoint = comm.first_text(root ? summary.last_checkpoint.string() : std::string());
      dist::share_layout_from_root(comm, sim.particles());
      read = share_checkpoint_values(comm, read);
    }
    const auto& [header, values] = read;
    SimulationClock clock{header.step, header.time, find_value(values, "clock.previous_dt").value_or(0),
                          find_value(values, "clock.dt_floor").value_or(0)};
    sim.resume(clock, values);
    summary.particles = static_cast<std::size_t>(sim.global_count());  // the checkpoint's (inlets, outlets)
    for (Observer<Real>* o : observers) o->load_state(values);
    summary.first_step = header.step;
    end = RunEnd::choose(scene, options, header.step, header.time, &values);
    if (!(end.to_time ? sim.time() < end.time : sim.step_count() < end.step))
      throw std::invalid_argument(fmt::format(
          "--resume {}: the run already reached the end it was given ({}; its newest checkpoint is at step {}, "
          "t = {:.6g}); to go further give --steps N (N more steps) or --until T (a later time)",
          options.out_dir.string(), end.describe(), sim.step_count(), sim.time()));
  } else {
    end = RunEnd::choose(scene, options, 0, 0.0, nullptr);
    if (root)
      io::write_file_atomic(folder->claim(options.out_dir / "scene.toml"),
                            scene.toml.empty() ? std::string("# built in code\n") : scene.toml);
  }
  auto running = [&] { return end.to_time ? sim.time() < end.time : sim.step_count() < end.step; };

  // One stage of the run: a blow-up or a failed write ends the run with its
  // message in the summary (on several ranks: on every rank, agree()).
  auto stage = [&](auto&& body) {
    Failure failure;
    try {
      body();
    } catch (const SimulationError& e) {
      failure = {e.what(), std::string(to_string(e.cause()))};
    } catch (const io::IoError& e) {
      failure = {fmt::format("writing output failed at step {}: {}", sim.step_count(), e.what()), ""};
    } catch (const std::filesystem::filesystem_error& e) {
      failure = {fmt::format("writing output failed at step {}: {}", sim.step_count(), e.what()), ""};
    }
    if (on_ranks) failure = agree(comm, failure);
    summary.error = failure.error;
    summary.blow_up = failure.blow_up;
    return failure.error.empty();
  };
  // A stop asked on any rank (mpirun passes SIGINT and SIGTERM to every rank).
  auto stop_asked = [&] {
    double asked[1] = {options.stop && options.stop->load() ? 1.0 : 0.0};
    if (on_ranks) comm.max(asked);
    return asked[0] > 0;
  };

  dist::Traffic step_traffic;  // this rank's, inside the steps (not the set-up, frames or checkpoints)
  bool going = stage([&] {
    if (!options.resume) {
      // Phase "start": the first evaluation, apart from the steps' own time
      // (on ranks also rank 0's scatter of the set it built, and the first
      // distribution in key order).
      ScopedPhase phase(sim.timers(), "start");
      sim.start();  // solvers fill their fields (density, potential) here
    }
    summary.bytes_per_particle = bytes_per_particle(sim);
    for (Observer<Real>* o : observers) o->on_start(sim, options.resume);
  });
  while (going && running()) {
    going = stage([&] {
      std::optional<double> land;
      if (adaptive) {  // land exactly on the end time and on the observers' next times
        if (end.to_time) land = end.time;
        for (const Observer<Real>* o : observers)
          if (const auto t = o->next_time(sim); t && (!land || *t < *land)) land = t;
      }
      const dist::Traffic before = comm.traffic();
      sim.step(land);
      step_traffic += comm.traffic() - before;
      for (Observer<Real>* o : observers) o->on_step(sim);
    });
    if (going && stop_asked()) {
      summary.interrupted = stage([&] { checkpoints->write(sim); });
      break;
    }
  }
  if (going && !summary.interrupted) stage([&] {
      for (Observer<Real>* o : observers) o->on_finish(sim);
    });

  summary.failed_checks = guard->failed_checks();
  if (!checkpoints->last().empty()) summary.last_checkpoint = checkpoints->last();
  summary.steps = sim.step_count() - summary.first_step;
  summary.sim_time = sim.time();
  summary.wall_seconds = progress->wall();
  summary.steps_per_second = summary.wall_seconds > 0 ? static_cast<double>(summary.steps) / summary.wall_seconds : 0;
  summary.phases = sim.timers().phases();
  summary.frames = frames->frames();
  summary.particles_end = static_cast<std::size_t>(sim.global_count());
  if (inlets) {
    summary.metrics.emplace_back("inlet_particles", double(inlets->emitted()));
    summary.metrics.emplace_back("outlet_particles", double(inlets->removed()));
  }
  for (const auto& s : sim.solvers()) s->add_metrics(summary.metrics);
  sim.stepper().add_metrics(summary.metrics);
  if (const auto error = diagnostics->energy_error()) summary.metrics.emplace_back("relative_energy_error", *error);
  if (sim.ranks()) {
    if (sim.ranks()->active()) {
      summary.metrics.emplace_back("sorts", double(sim.ranks()->sorts()));
      // The balance (dist/rank_order.hpp): how often the cuts moved, and the
      // largest rank's work over the mean at the last sort.
      summary.metrics.emplace_back("rebalances", double(sim.ranks()->rebalances()));
      summary.metrics.emplace_back("rank_imbalance", sim.ranks()->imbalance());
    }
    // Communication per step (dist::Traffic) and the solvers' own per-rank
    // figures (halo and imported-tree fractions), as mean and max over ranks.
    const double steps = std::max(double(summary.steps), 1.0);
    NamedValues mine{{"mpi_collectives_per_step", double(step_traffic.collectives) / steps},
                     {"mpi_messages_per_step", double(step_traffic.messages) / steps},
                     {"mpi_bytes_sent_per_step", double(step_traffic.bytes_sent) / steps},
                     {"mpi_bytes_received_per_step", double(step_traffic.bytes_received) / steps}};
    for (const auto& s : sim.solvers()) s->add_rank_metrics(mine);
    add_over_ranks(comm, mine, summary.metrics);
  } else if (sim.order().active()) {
    summary.metrics.emplace_back("sorts", double(sim.order().sorts()));
  }
  if (adaptive && progress->dt_max() > 0) {  // landing steps included
    summary.metrics.emplace_back("smallest_dt", progress->dt_min());
    summary.metrics.emplace_back("largest_dt", progress->dt_max());
  }
  return summary;
}

// What of a scene does not run on several ranks yet (its solvers as its precision makes them).
template <class Real>
std::string distributed_support_of(const scene::Scene& scene) {
  if (scene.nbody) {
    const std::string no = gravity::GravityForce<Real>(*scene.nbody).distributed_support();
    if (!no.empty()) return "self-gravity with " + no;
  }
  if (scene.sph) {
    const std::string no = sph::SphFluid<Real>(*scene.sph).distributed_support();
    if (!no.empty()) return no;
  }
  // Boundary particles (box.walls = "particles", obstacles, moving ones),
  // probes, obstacle forces, inlets and outlets run on ranks too.
  return {};
}

}  // namespace

std::string distributed_support(const scene::Scene& scene) {
  return scene.precision == scene::Precision::Float ? distributed_support_of<float>(scene)
                                                    : distributed_support_of<double>(scene);
}

void check_memory(const scene::Scene& scene, const dist::Communicator* ranks) {
  std::vector<RankHost> hosts;
  if (ranks && ranks->distributed()) {
    // Where each rank runs and what it sees free: ranks on one host share its memory.
    char name[256] = {};
    if (gethostname(name, sizeof name - 1) != 0) name[0] = '\0';
    const std::string mine = fmt::format("{}\n{}", name, memory_available());
    dist::Bytes bytes(mine.size());
    std::memcpy(bytes.data(), mine.data(), mine.size());
    for (const dist::Bytes& b : ranks->all_gather(bytes)) {
      const std::string text(reinterpret_cast<const char*>(b.data()), b.size());
      const auto cut = text.rfind('\n');
      hosts.push_back({text.substr(0, cut), std::stoull(text.substr(cut + 1))});
    }
  }
  if (const std::string no = memory_refusal(scene, hosts); !no.empty()) throw std::invalid_argument(no);
}

RunSummary run_scene(const scene::Scene& scene, const RunOptions& options,
                     const std::function<void(const RunProgress&)>& on_progress) {
  check_memory(scene, options.ranks);
  if (options.threads > 0) parallel::set_thread_count(options.threads);
  const auto frame = static_cast<std::uintmax_t>(footprint(scene).frame);
  return scene.precision == scene::Precision::Float ? run_typed<float>(scene, options, frame, on_progress)
                                                    : run_typed<double>(scene, options, frame, on_progress);
}

}  // namespace swirl::sim
