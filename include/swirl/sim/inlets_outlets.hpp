// InletsAndOutlets<Real>: the observer that changes the particle count of a
// run: the scene's inlets add fluid particles, its outlets remove them
// (scene::Inlet, scene::Outlet; docs/sph.md, Inlets and outlets).
//
// After every step, at time t:
//   outlets  every fluid particle (not a boundary particle) inside an outlet's
//            box is removed, the others keeping their order;
//   inlets   every layer k whose time t_k = start + k·spacing/speed is ≤ t
//            (and < stop) and not yet emitted is added at the end of the set:
//            one particle per point of the inlet's square pattern (the points
//            a·s·u + b·s·v of the disc's plane strictly within its radius,
//            a, b integers, s the inlet's spacing, u, v unit vectors across the
//            disc), moved the distance speed·(t − t_k) the layer has travelled
//            since its time, with velocity speed·direction, the inlet's mass,
//            kind fluid and a fresh id (the next id: one more than the largest
//            the run has had, ids are never reused).
// Layers leave every spacing/speed, so the fluid enters at the rest density:
// rate = (points per layer)·speed/spacing particles per second, points per
// layer ≈ π r²/s². Then Simulation::change_particles() makes the state whole
// (the order, the forces at the new state, the limits): one extra force
// evaluation per step in which the count changed.
//
// State: the layers each inlet has emitted, the next id and the counts added
// and removed, saved in checkpoints ("inlets.*"), so that a resumed run emits
// exactly where the uninterrupted one would have. Acts first among the
// observers, so frames, diagnostics and checkpoints see the changed set.
// Everything here is serial and in double: the same bits for any thread count.
// Several ranks: every rank decides the same layers (a function of t), each
// removes its own leaving particles, and only the last rank appends the new
// ones, at the end of the global order as one rank appends them; whether
// anything changes, the largest id and the count removed are decided over
// all ranks. The same bits for any rank count.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/named_values.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/sim/observer.hpp"

namespace swirl::sim {

// The offsets of one inlet layer's particles from its disc's centre (m), in a
// fixed order (b outer, a inner, both ascending).
inline std::vector<Vec3d> inlet_pattern(const scene::Inlet& inlet) {
  const Vec3d e = inlet.direction * (1 / norm(inlet.direction));
  const auto [u, v] = basis_around(e);
  const double s = inlet.spacing, r2 = inlet.radius * inlet.radius;
  const auto reach = static_cast<std::int64_t>(std::floor(inlet.radius / s));
  std::vector<Vec3d> out;
  for (std::int64_t b = -reach; b <= reach; ++b)
    for (std::int64_t a = -reach; a <= reach; ++a) {
      const double x = s * static_cast<double>(a), y = s * static_cast<double>(b);
      if (x * x + y * y < r2) out.push_back(u * x + v * y);
    }
  return out;
}

template <class Real>
class InletsAndOutlets final : public Observer<Real> {
 public:
  explicit InletsAndOutlets(const scene::Scene& scene)
      : inlets_(scene.inlets), outlets_(scene.outlets), layers_(scene.inlets.size(), 0) {
    for (const auto& inlet : inlets_) patterns_.push_back(inlet_pattern(inlet));
  }

  std::string_view name() const override { return "inlets"; }

  void on_start(Simulation<Real>& sim, bool resumed) override {
    if (resumed && have_next_id_) return;
    // A fresh run (or a state without the value): one past the largest id (of all ranks).
    const auto& ids = sim.particles().id;
    std::uint64_t next = ids.empty() ? 0 : *std::max_element(ids.begin(), ids.end()) + 1;
    if (const dist::Communicator* comm = communicator(sim))
      for (const std::uint64_t n : comm->all_gather(next)) next = std::max(next, n);
    next_id_ = next;
  }

  void on_step(Simulation<Real>& sim) override {
    const double t = sim.time();
    const ParticleSet<Real>& p = sim.particles();
    // What leaves: fluid particles in an outlet.
    const std::size_t kind_field = p.find_int_field(kKindField);
    const std::int32_t* kind = kind_field == ParticleSet<Real>::npos ? nullptr : p.int_field(kind_field).data();
    const auto leaves = [&](std::size_t i) {
      if (kind && is_boundary(kind[i])) return false;
      const Vec3d x = p.position.get(i).template cast<double>();
      for (const auto& o : outlets_)
        if (o.region.contains(x)) return true;
      return false;
    };
    bool any_leaves = false;
    for (std::size_t i = 0; i < p.size() && !any_leaves && !outlets_.empty(); ++i) any_leaves = leaves(i);
    const dist::Communicator* comm = communicator(sim);
    if (comm && !outlets_.empty()) any_leaves = comm->sum(std::uint64_t{any_leaves}) != 0;
    // What enters: the layers due by t.
    struct Entering {
      Vec3d x, v;
      double m;
    };
    std::vector<Entering> entering;
    for (std::size_t k = 0; k < inlets_.size(); ++k) {
      const scene::Inlet& in = inlets_[k];
      const Vec3d e = in.direction * (1 / norm(in.direction));
      const double period = in.spacing / in.speed;
      for (;;) {
        const double tk = in.start + static_cast<double>(layers_[k]) * period;
        if (tk > t || (in.stop && tk >= *in.stop)) break;
        const Vec3d centre = in.center + e * (in.speed * (t - tk));
        for (const Vec3d& offset : patterns_[k]) entering.push_back({centre + offset, e * in.speed, in.mass});
        ++layers_[k];
      }
    }
    if (!any_leaves && entering.empty()) return;
    // On ranks the new particles are the last rank's (the end of the global order).
    const bool appends = !comm || comm->rank() + 1 == comm->size();
    sim.change_particles([&](ParticleSet<Real>& q) {
      const std::uint64_t removed = q.remove_if(leaves);
      removed_ += comm && any_leaves ? comm->sum(removed) : removed;
      if (!appends) {
        next_id_ += entering.size();
        emitted_ += entering.size();
        return;
      }
      const std::size_t first = q.size();
      q.resize(first + entering.size());
      for (std::size_t j = 0; j < entering.size(); ++j) {
        const std::size_t i = first + j;
        q.position.set(i, entering[j].x.template cast<Real>());
        q.velocity.set(i, entering[j].v.template cast<Real>());
        q.mass[i] = static_cast<Real>(entering[j].m);
        q.id[i] = next_id_++;
        // kind: 0, fluid (resize zeroes new entries).
      }
      emitted_ += entering.size();
    });
  }

  void save_state(NamedValues& out) const override {
    for (std::size_t k = 0; k < layers_.size(); ++k)
      out.emplace_back(fmt::format("inlets.{}.layers", k), static_cast<double>(layers_[k]));
    out.emplace_back("inlets.next_id", static_cast<double>(next_id_));
    out.emplace_back("inlets.emitted", static_cast<double>(emitted_));
    out.emplace_back("inlets.removed", static_cast<double>(removed_));
  }

  void load_state(const NamedValues& values) override {
    for (std::size_t k = 0; k < layers_.size(); ++k)
      layers_[k] = static_cast<std::uint64_t>(find_value(values, fmt::format("inlets.{}.layers", k)).value_or(0));
    const auto next = find_value(values, "inlets.next_id");
    have_next_id_ = next.has_value();
    next_id_ = static_cast<std::uint64_t>(next.value_or(0));
    emitted_ = static_cast<std::uint64_t>(find_value(values, "inlets.emitted").value_or(0));
    removed_ = static_cast<std::uint64_t>(find_value(values, "inlets.removed").value_or(0));
  }

  // Particles added by the inlets and removed by the outlets since the run began.
  std::uint64_t emitted() const { return emitted_; }
  std::uint64_t removed() const { return removed_; }
  // Each inlet's particles per layer.
  std::size_t layer_size(std::size_t inlet) const { return patterns_[inlet].size(); }

 private:
  // The run's ranks when there are several, else null.
  static const dist::Communicator* communicator(const Simulation<Real>& sim) {
    return sim.ranks() && sim.ranks()->comm().distributed() ? &sim.ranks()->comm() : nullptr;
  }

  std::vector<scene::Inlet> inlets_;
  std::vector<scene::Outlet> outlets_;
  std::vector<std::vector<Vec3d>> patterns_;
  std::vector<std::uint64_t> layers_;
  std::uint64_t next_id_ = 0;
  bool have_next_id_ = false;
  std::uint64_t emitted_ = 0, removed_ = 0;
};

// Compiled once, in src/sim/inlets_outlets.cpp: users link the float and double copies
// instead of compiling them again.
extern template class InletsAndOutlets<float>;
extern template class InletsAndOutlets<double>;

}  // namespace swirl::sim
