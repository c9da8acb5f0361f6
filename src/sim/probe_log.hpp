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
// On several ranks (Simulation::ranks()) every rank calls the observer at the
// same steps, and a row is the one-rank row byte for byte. The one-rank sums
// are serial over the memory order, which is the ranks' particles in rank
// order, and a float sum cut at the ranks and added again is not the same
// bits; so the terms are gathered, not partial sums: each rank sends rank 0
// its own particles that can reach a probe (a point's fluid particles within
// h, a line's within h of it: the only ones whose weight is not 0) and the
// per-particle force and torque terms of its own obstacle particles, all in
// its memory order; rank 0 concatenates them in rank order (the global
// order) and sums them as one rank does, over the same particles in the
// same order (a particle whose weight is 0 adds nothing there either). A
// row costs one gather of a few dozen particles per probe and 56 B per
// obstacle particle; ghosts are never sent (each particle once, by its owner).
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

#include "swirl/dist/communicator.hpp"
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
    if (!folder_ || !std::filesystem::exists(path_)) return;  // on ranks: rank 0 writes
    std::istringstream in(io::read_text_file(path_));
    std::string line;
    std::getline(in, line);  // the header, as this version writes it (the scene hash fixes the probes)
    for (std::size_t k = 0; k < rows_ && std::getline(in, line); ++k) text_ += line + "\n";
  }

 private:
  void add_row(Simulation<Real>& sim) {
    ScopedPhase phase(sim.timers(), "output");
    const dist::Communicator* comm = sim.ranks() ? &sim.ranks()->comm() : nullptr;
    const ParticleSet<Real>& p = sim.particles();  // on ranks: this rank's own particles
    std::vector<double> row{sim.time()};
    if (!probes_.empty()) {
      const ParticleSet<Real>& at = comm ? near_probes(*comm, p) : p;
      for (const auto& probe : probes_)
        row.push_back(probe.point ? sampler_->pressure(at, *probe.point) : sampler_->height(at, probe.line[0], probe.line[1]));
    }
    if (!obstacles_.empty()) add_obstacles(sim, comm, row);
    ++rows_;
    last_step_ = sim.step_count();
    if (comm && !comm->is_root()) return;  // its row holds its share only; rank 0 writes
    for (std::size_t k = 0; k < row.size(); ++k) text_ += fmt::format("{}{:.9g}", k ? "," : "", row[k]);
    text_ += "\n";
    if (folder_) io::write_file_atomic(folder_->claim(path_), text_);
  }

  // On ranks, collective: the fluid particles of every rank that can reach a
  // probe (ProbeSampler::reaches_point, reaches_line), their position, mass,
  // density and pressure, on rank 0 in global order (empty on the others).
  const ParticleSet<Real>& near_probes(const dist::Communicator& comm, const ParticleSet<Real>& p) {
    const std::size_t k = p.find_int_field(kKindField);
    const std::int32_t* kind = k == ParticleSet<Real>::npos ? nullptr : p.int_field(k).data();
    constexpr std::size_t kReals = 6;
    std::vector<Real> mine;
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (kind && is_boundary(kind[j])) continue;
      bool reaches = false;
      for (const auto& probe : probes_)
        if (probe.point ? sampler_->reaches_point(p, j, *probe.point) : sampler_->reaches_line(p, j, probe.line[0], probe.line[1])) {
          reaches = true;
          break;
        }
      if (reaches)
        mine.insert(mine.end(), {p.position.x[j], p.position.y[j], p.position.z[j], p.mass[j], p.density[j], p.pressure[j]});
    }
    std::vector<Real> all;
    for (const dist::Bytes& b : comm.gather_to_root(dist::to_bytes(std::span<const Real>(mine))))
      dist::append_values(b, all, "probes");
    near_ = ParticleSet<Real>(all.size() / kReals);
    for (std::size_t i = 0; i < near_.size(); ++i) {
      const Real* v = all.data() + kReals * i;
      near_.position.set(i, Vec3<Real>{v[0], v[1], v[2]});
      near_.mass[i] = v[3], near_.density[i] = v[4], near_.pressure[i] = v[5];
    }
    return near_;
  }

  // Each obstacle's force F = Σ F_b and torque Σ (x_b − c) × F_b over its
  // boundary particles, in memory order (c: the centre at the row's time).
  // Every particle's terms first (on ranks: each rank its own, gathered to
  // rank 0 in rank order), then the sums, so one rank and several run the
  // same additions in the same order.
  void add_obstacles(Simulation<Real>& sim, const dist::Communicator* comm, std::vector<double>& row) {
    sph::SphFluid<Real>* fluid = nullptr;
    for (const auto& s : sim.solvers())
      if (auto* f = dynamic_cast<sph::SphFluid<Real>*>(s.get())) fluid = f;
    if (!fluid) throw std::logic_error("ProbeLog: obstacle forces without the SPH solver");
    const ParticleSet<Real>& p = sim.particles();
    fluid->boundary_forces(p, block_size_, forces_);  // collective on ranks
    std::vector<Vec3d> centres;  // a moving obstacle's torque is about its centre where it is now
    for (const auto& o : obstacles_) centres.push_back(o.centre_at(sim.time()));
    constexpr std::size_t kTerm = 7;  // obstacle, F, (x − c) × F
    std::vector<double> terms;
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
      terms.insert(terms.end(), {double(k), fx, fy, fz, ry * fz - rz * fy, rz * fx - rx * fz, rx * fy - ry * fx});
    }
    if (comm) {
      const dist::Bytes bytes = dist::to_bytes(std::span<const double>(terms));
      terms.clear();
      for (const dist::Bytes& b : comm->gather_to_root(bytes)) dist::append_values(b, terms, "obstacle forces");
    }
    std::vector<std::array<double, 6>> sums(obstacles_.size(), std::array<double, 6>{});
    for (std::size_t t = 0; t + kTerm <= terms.size(); t += kTerm) {
      auto& s = sums[static_cast<std::size_t>(terms[t])];
      for (std::size_t c = 0; c < 6; ++c) s[c] += terms[t + 1 + c];
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
  ParticleSet<Real> near_;      // on ranks, rank 0: the particles near the probes (scratch)
  std::string text_;
  std::size_t rows_ = 0;
  std::uint64_t last_step_ = 0;
};

}  // namespace swirl::sim
