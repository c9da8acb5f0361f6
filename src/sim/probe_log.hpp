// probes.csv (docs/sph.md, Probes): the run's observer that records the
// scene's [[probes]] (pressure at points, water height along vertical lines,
// sph/probes.hpp) and, with output.obstacle_forces, the force and torque the
// fluid exerts on each obstacle and on walls of particles
// (SphFluid::boundary_forces), one row per probe time.
//
// When: at the start (time 0), then at the first step at or past each
// multiple of output.probes_interval (output.interval when 0; adaptive steps
// land on them), and at the end; the diagnostics log's rule. The file is
// rewritten atomically after each row, through the run folder.
//
// Obstacles: the ids of each one's boundary particles (scene::obstacle_ids():
// make_particles numbers them in source order, and ids travel with the
// particles), so no particle field and no checkpoint change is needed. The
// sums run serially in memory order in double: the same bits for any thread
// count and after a resume (which restores the order).
//
// Resume: the rows written before the checkpoint are kept (read back from the
// file, as many as the checkpoint says), the later ones replaced; a resumed
// run's file is byte for byte the uninterrupted run's.
#pragma once

#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/run_folder.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/sim/observer.hpp"
#include "swirl/sim/run.hpp"
#include "swirl/sph/probes.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace swirl::sim {

template <class Real>
class ProbeLog final : public Observer<Real> {
 public:
  ProbeLog(const scene::Scene& scene, const RunOptions& options, io::RunFolder* folder)
      : path_(options.out_dir / "probes.csv"),
        schedule_(scene.probes_interval > 0 ? scene.probes_interval : scene.output_interval, scene.dt),
        block_size_(scene.block_size), probes_(scene.probes), folder_(folder) {
    if (!scene.sph) throw std::logic_error("ProbeLog: a scene without [sph]");
    sampler_.emplace(*scene.sph);
    if (scene.obstacle_forces) obstacles_ = scene::obstacle_ids(scene);
    std::string header = "time";
    for (const auto& probe : probes_) header += fmt::format(",{}_{}", probe.name, probe.point ? "pressure" : "height");
    for (const auto& o : obstacles_)
      for (const char* q : {"force_x", "force_y", "force_z", "torque_x", "torque_y", "torque_z"})
        header += fmt::format(",{}_{}", o.name, q);
    text_ = header + "\n";
  }

  std::string_view name() const override { return "probes"; }
  void on_start(Simulation<Real>& sim, bool resumed) override {
    // DFSPH records its density solve's reaction on the walls from the first step on.
    if (!obstacles_.empty())
      for (const auto& s : sim.solvers())
        if (auto* fluid = dynamic_cast<sph::SphFluid<Real>*>(s.get())) fluid->record_boundary_reactions(true);
    if (!resumed) add_row(sim);
  }
  void on_step(Simulation<Real>& sim) override {
    if (!schedule_.due(sim.time())) return;
    add_row(sim);
    schedule_.acted(sim.time());
  }
  void on_finish(Simulation<Real>& sim) override {
    if (last_step_ != sim.step_count() || rows_ == 0) add_row(sim);
  }
  std::optional<double> next_time(const Simulation<Real>&) const override { return schedule_.next_time(); }

  void save_state(NamedValues& out) const override {
    out.insert(out.end(), {{"probes.rows", double(rows_)},
                           {"probes.next", double(schedule_.next_index())},
                           {"probes.last_step", double(last_step_)}});
  }
  // Continues the file, keeping the rows written before the checkpoint.
  void load_state(const NamedValues& values) override {
    rows_ = static_cast<std::size_t>(find_value(values, "probes.rows").value_or(0));
    schedule_.set_next_index(static_cast<std::uint64_t>(find_value(values, "probes.next").value_or(1)));
    last_step_ = static_cast<std::uint64_t>(find_value(values, "probes.last_step").value_or(0));
    if (!std::filesystem::exists(path_)) return;
    std::istringstream in(io::read_text_file(path_));
    std::string line;
    std::getline(in, line);  // the header, as this version writes it (the scene hash fixes the probes)
    for (std::size_t k = 0; k < rows_ && std::getline(in, line); ++k) text_ += line + "\n";
  }

 private:
  void add_row(Simulation<Real>& sim) {
    ScopedPhase phase(sim.timers(), "output");
    const ParticleSet<Real>& p = sim.particles();  // one rank only (probes are refused on several)
    std::vector<double> row{sim.time()};
    for (const auto& probe : probes_)
      row.push_back(probe.point ? sampler_->pressure(p, *probe.point) : sampler_->height(p, probe.line[0], probe.line[1]));
    if (!obstacles_.empty()) add_obstacles(sim, row);
    for (std::size_t k = 0; k < row.size(); ++k) text_ += fmt::format("{}{:.9g}", k ? "," : "", row[k]);
    text_ += "\n";
    ++rows_;
    last_step_ = sim.step_count();
    if (folder_) io::write_file_atomic(folder_->claim(path_), text_);
  }

  // Each obstacle's force F = Σ F_b and torque Σ (x_b − c) × F_b over its
  // boundary particles, in memory order (c: the centre at the row's time).
  void add_obstacles(const Simulation<Real>& sim, std::vector<double>& row) {
    const auto* fluid = sim.template find_solver<sph::SphFluid<Real>>();
    if (!fluid) throw std::logic_error("ProbeLog: obstacle forces without the SPH solver");
    const ParticleSet<Real>& p = sim.particles();
    fluid->boundary_forces(p, block_size_, forces_);
    std::vector<std::array<double, 6>> sums(obstacles_.size(), std::array<double, 6>{});
    std::vector<Vec3d> centres;  // a moving obstacle's torque is about its centre where it is now
    for (const auto& o : obstacles_) centres.push_back(o.centre_at(sim.time()));
    for (std::size_t i = 0; i < p.size(); ++i) {
      const std::uint64_t id = p.id[i];
      // The obstacles' id ranges are disjoint and in increasing order.
      const auto it = std::upper_bound(obstacles_.begin(), obstacles_.end(), id,
                                       [](std::uint64_t v, const scene::ObstacleIds& o) { return v < o.first; });
      if (it == obstacles_.begin()) continue;
      const auto k = static_cast<std::size_t>(it - obstacles_.begin()) - 1;
      const scene::ObstacleIds& o = obstacles_[k];
      if (id >= o.first + o.count) continue;
      const double fx = forces_[3 * i], fy = forces_[3 * i + 1], fz = forces_[3 * i + 2];
      const Vec3d& c = centres[k];
      const double rx = double(p.position.x[i]) - c.x, ry = double(p.position.y[i]) - c.y,
                   rz = double(p.position.z[i]) - c.z;
      auto& s = sums[k];
      s[0] += fx, s[1] += fy, s[2] += fz;
      s[3] += ry * fz - rz * fy, s[4] += rz * fx - rx * fz, s[5] += rx * fy - ry * fx;
    }
    for (const auto& s : sums) row.insert(row.end(), s.begin(), s.end());
  }

  std::filesystem::path path_;
  IntervalSchedule schedule_;
  std::size_t block_size_;
  std::vector<scene::Probe> probes_;
  std::vector<scene::ObstacleIds> obstacles_;
  std::optional<sph::ProbeSampler> sampler_;
  io::RunFolder* folder_;  // null: nothing written (a run without a folder)
  std::vector<double> forces_;  // per particle, 3 each (scratch)
  std::string text_;
  std::size_t rows_ = 0;
  std::uint64_t last_step_ = 0;
};

}  // namespace swirl::sim
