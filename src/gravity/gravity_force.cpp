#include "swirl/gravity/gravity_force.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "swirl/dist/rank_order.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {
FmmSettings fmm_settings(const GravitySettings& g) {
  validate(g);  // before the conversion: fmm_order is checked here
  FmmSettings f;
  f.order = int(g.fmm_order);
  f.opening = g.opening;
  f.softening = g.softening;
  f.bucket_size = g.bucket_size;
  return f;
}
}  // namespace

template <class Real>
GravityForce<Real>::GravityForce(const GravitySettings& settings, const SelfGravityOptions& options)
    : settings_(settings), options_(options), tree_(settings), fmm_(fmm_settings(settings)) {
  if (!(options.G > 0) || !std::isfinite(options.G))
    throw std::invalid_argument("gravity: the gravitational constant G must be finite and > 0");
  if (!(options.eta > 0) || !std::isfinite(options.eta))
    throw std::invalid_argument("gravity: the time-step factor eta must be finite and > 0");
}

template <class Real>
void GravityForce<Real>::set_softening(double softening) {
  GravitySettings changed = settings_;
  changed.softening = softening;
  validate(changed);  // std::invalid_argument for a negative or non-finite ε
  settings_ = changed;
  tree_ = BarnesHut<Real>(settings_);  // the trees read ε from their settings at each evaluation
  fmm_ = Fmm<Real>(fmm_settings(settings_));
}

template <class Real>
bool GravityForce<Real>::views_order() const {
  if (settings_.method == Method::Fmm) return settings_.reorder;
  return settings_.method == Method::BarnesHut && settings_.reorder && tree_.uses_linear_tree();
}

template <class Real>
std::string GravityForce<Real>::distributed_support() const {
  if (settings_.method == Method::Direct || settings_.method == Method::Fmm) return {};  // replicated
  if (settings_.method != Method::BarnesHut) return fmt::format("nbody.method = \"{}\"", to_string(settings_.method));
  if (!views_order()) return "a Barnes-Hut tree other than the linear octree over the particle order";
  if (settings_.walk != Walk::Group) return "nbody.walk = \"particle\"";
  return {};
}

template <class Real>
std::vector<std::uint64_t> GravityForce<Real>::rank_cuts(const dist::Communicator& comm,
                                                         std::span<const std::uint64_t> keys,
                                                         std::vector<std::uint64_t> cuts) const {
  return group_aligned_cuts(comm, keys, cuts, tree_.linear_settings());
}

template <class Real>
void GravityForce<Real>::add_rank_costs(std::span<std::uint64_t> costs) const {
  if (walked_on_ranks_ && costs.size() == field_.size()) essential_.add_walk_costs(costs);
}

template <class Real>
void GravityForce<Real>::declare_fields(ParticleSet<Real>& p) {
  p.add_field("potential", 1);
}

template <class Real>
spatial::OrderRequest GravityForce<Real>::order_request() const {
  // Nodes must bound their particles, so the keys must be this step's: no tolerance.
  if (views_order()) return {true, 0, 0, spatial::CellOrder::Morton};
  return {};
}

namespace {

// The whole set's positions and masses into `all` (resized; its other
// fields untouched), in rank order — the one-rank memory order
// (dist/rank_order.hpp) — and, when keys is given, the whole order's keys
// (each rank's keys() in rank order: the one-rank keys). O(N) memory per
// rank, kept by the caller between evaluations. Collective.
template <class Real>
void gather_whole(const dist::RankOrder<Real>& order, const ParticleSet<Real>& p, const char* what,
                  ParticleSet<Real>& all, std::vector<std::uint64_t>* keys = nullptr) {
  const dist::Communicator& comm = order.comm();
  const std::size_t n = p.size();
  // This rank's message: its x, y, z and m arrays one after the other.
  dist::Bytes mine(4 * n * sizeof(Real));
  const AlignedVector<Real>* arrays[4] = {&p.position.x, &p.position.y, &p.position.z, &p.mass};
  for (std::size_t a = 0; a < 4 && n > 0; ++a)
    std::memcpy(mine.data() + a * n * sizeof(Real), arrays[a]->data(), n * sizeof(Real));
  all.resize(order.global_count());
  AlignedVector<Real>* into[4] = {&all.position.x, &all.position.y, &all.position.z, &all.mass};
  std::size_t at = 0;
  for (const dist::Bytes& b : comm.all_gather(mine)) {
    const std::size_t count = b.size() / (4 * sizeof(Real));
    if (b.size() % (4 * sizeof(Real)) != 0 || at + count > all.size())
      throw std::runtime_error(std::string(what) + ": a rank sent a partial set");
    for (std::size_t a = 0; a < 4 && count > 0; ++a)
      std::memcpy(into[a]->data() + at, b.data() + a * count * sizeof(Real), count * sizeof(Real));
    at += count;
  }
  if (at != all.size()) throw std::runtime_error(std::string(what) + ": the ranks hold another particle count");
  if (keys) {
    keys->clear();
    keys->reserve(all.size());
    for (const dist::Bytes& b : comm.all_gather(dist::to_bytes(order.keys()))) dist::append_values(b, *keys, what);
    if (keys->size() != all.size()) throw std::runtime_error(std::string(what) + ": the ranks hold another key count");
  }
}

// Flags, over the whole set, this rank's own active particles (the others
// 0): the replicated methods then compute only what this rank keeps. Returns
// their number.
std::uint64_t flag_own_active(std::size_t first, std::size_t n, const ActiveSet& active,
                              std::vector<std::int32_t>& whole_active, std::size_t whole_count) {
  whole_active.assign(whole_count, 0);
  std::uint64_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    whole_active[first + i] = active.contains(i) ? 1 : 0;
    count += std::uint64_t(whole_active[first + i]);
  }
  return count;
}

// This rank's own particles' entries of the whole set's field.
template <class Real>
void keep_own(const GravityField<Real>& whole, std::size_t first, std::size_t n, GravityField<Real>& own) {
  own.resize(n);
  for (int a = 0; a < 3; ++a)
    std::copy_n(whole.acceleration[a].data() + first, n, own.acceleration[a].data());
  std::copy_n(whole.potential.data() + first, n, own.potential.data());
}

}  // namespace

template <class Real>
void GravityForce<Real>::add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) {
  if (ctx.ranks && settings_.method == Method::Direct) {
    // Replicated: every rank gathers the whole set (gather_whole) and sums over
    // all of it for its own active particles with the one-rank direct_sum(),
    // whose sum for a particle depends only on the whole set's order: the
    // one-rank bits (O(N) memory per rank, as the O(N²) method's sizes allow).
    const dist::RankOrder<Real>& order = *ctx.ranks;
    const auto t0 = std::chrono::steady_clock::now();
    gather_whole(order, p, "direct sum on ranks", whole_);
    const std::size_t first = order.first_global_index();
    const std::uint64_t active_count = flag_own_active(first, p.size(), ctx.active, whole_active_, whole_.size());
    direct_sum(whole_, Real(settings_.softening), ctx.block_size, whole_field_, ActiveSet{whole_active_.data(), 1});
    keep_own(whole_field_, first, p.size(), field_);
    stats_ = GravityStats{};
    stats_.walked = order.comm().sum(active_count);
    stats_.mean_nodes_visited = double(ctx.ranks->global_count() - 1);
    stats_.force_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  } else if (ctx.ranks && settings_.method != Method::Fmm) {
    // The locally essential tree over the global order (essential_tree.hpp):
    // every particle's field is the one-rank group walk's, bit for bit.
    if (const std::string no = distributed_support(); !no.empty())
      throw std::invalid_argument("self-gravity on several ranks: " + no + " does not run on several ranks yet");
    const dist::RankOrder<Real>& order = *ctx.ranks;
    const spatial::KeyFrame& f = order.frame();
    const auto t0 = std::chrono::steady_clock::now();
    // With block time steps only the active particles' groups are exchanged and walked.
    essential_.build(order.comm(), p, order.keys(), order.first_global_index(), order.cut_keys(),
                     KeyCube{f.corner, f.root_side()}, tree_.linear_settings(), ctx.block_size, ctx.active);
    const auto t1 = std::chrono::steady_clock::now();
    imported_nodes_ += double(essential_.stats().nodes_received);
    imported_particles_ += double(essential_.stats().particles_received);
    own_particles_ += double(p.size());
    const WalkCounts counts = essential_.evaluate(field_);
    walked_on_ranks_ = ctx.active.all();  // walk costs are those of a full evaluation
    // The one-rank figures: exact integer sums over ranks, then its divisions.
    std::uint64_t active = 0;
    if (ctx.active.all())
      active = p.size();
    else
      for (std::size_t i = 0; i < p.size(); ++i) active += ctx.active.contains(i);
    std::uint64_t sums[3] = {counts.nodes, counts.multipoles + counts.pairs, active};
    order.comm().sum(sums);
    const double n = double(sums[2]);
    stats_ = GravityStats{};
    stats_.walked = sums[2];
    stats_.trees = 1;
    stats_.nodes = essential_.stats().tree_nodes;
    stats_.tree_bytes = essential_.tree().bytes();
    stats_.mean_nodes_visited = n > 0 ? double(sums[0]) / n : 0.0;
    stats_.mean_interactions = n > 0 ? double(sums[1]) / n : 0.0;
    stats_.tree_build_seconds = std::chrono::duration<double>(t1 - t0).count();
    stats_.force_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  } else if (settings_.method == Method::Direct) {
    const auto t0 = std::chrono::steady_clock::now();
    direct_sum(p, Real(settings_.softening), ctx.block_size, field_, ctx.active);
    stats_ = GravityStats{};
    stats_.mean_nodes_visited = p.empty() ? 0.0 : double(p.size() - 1);
    for (std::size_t i = 0; i < p.size(); ++i) stats_.walked += ctx.active.contains(i);
    stats_.force_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  } else if (settings_.method == Method::Fmm) {
    // The active particles' field (fmm.hpp: the interactions of active cells
    // only, each active particle's field the full evaluation's bits); the
    // loop below writes the active ones.
    std::size_t whole_count = p.size();
    std::uint64_t computed = 0;
    if (ctx.ranks) {
      // Several ranks, replicated: every rank gathers the whole set (and the
      // order's keys) in the one-rank memory order and runs the one-rank FMM
      // over all of it with its own active particles as the active set,
      // keeping their field: the one-rank bits. The tree and the upward pass
      // are every rank's; the interactions divide among the ranks.
      const dist::RankOrder<Real>& order = *ctx.ranks;
      const auto& f = order.frame();
      const bool sorted = views_order() && order.valid() && f.curve == spatial::CellOrder::Morton;
      gather_whole(order, p, "the FMM on ranks", whole_, sorted ? &whole_keys_ : nullptr);
      const std::uint64_t own =
          flag_own_active(order.first_global_index(), p.size(), ctx.active, whole_active_, whole_.size());
      const ActiveSet own_active{whole_active_.data(), 1};
      if (sorted)
        fmm_.compute_sorted(whole_, whole_keys_, f.corner, f.root_side(), whole_field_, ctx.block_size, own_active);
      else
        fmm_.compute(whole_, whole_field_, ctx.block_size, own_active);
      keep_own(whole_field_, order.first_global_index(), p.size(), field_);
      whole_count = whole_.size();
      computed = order.comm().sum(own);
    } else if (const auto* order = ctx.order; views_order() && order && order->valid() &&
                                              order->frame().curve == spatial::CellOrder::Morton &&
                                              order->keys().size() == p.size()) {
      const auto& f = order->frame();
      fmm_.compute_sorted(p, order->keys(), f.corner, f.root_side(), field_, ctx.block_size, ctx.active);
      computed = fmm_.stats().active;
    } else {
      fmm_.compute(p, field_, ctx.block_size, ctx.active);
      computed = fmm_.stats().active;
    }
    const FmmStats& fs = fmm_.stats();
    stats_ = GravityStats{};
    const double n = whole_count == 0 ? 1.0 : double(whole_count);
    // Per particle: the cell interactions (M2L and P2P cell pairs) it takes part in
    // and the terms evaluated (two per mutual interaction: one for each side).
    stats_.mean_nodes_visited = 2.0 * double(fs.m2l + fs.p2p_cells) / n;
    stats_.mean_interactions = 2.0 * double(fs.m2l + fs.p2p_pairs) / n;
    stats_.walked = computed;
    stats_.trees = 1;
    stats_.nodes = fs.nodes;
    stats_.depth = fs.depth;
    stats_.leaves = fs.leaves;
    stats_.tree_bytes = fs.bytes;
    stats_.tree_build_seconds = fs.tree_seconds + fs.upward_seconds;
    stats_.force_seconds = fs.walk_seconds + fs.m2l_seconds + fs.p2p_seconds + fs.downward_seconds;
  } else {
    const auto* order = ctx.order;
    if (views_order() && order && order->valid() && order->frame().curve == spatial::CellOrder::Morton &&
        order->keys().size() == p.size()) {
      const auto& f = order->frame();
      tree_.compute_sorted(p, order->keys(), f.corner, f.root_side(), field_, ctx.block_size, ctx.active);
    } else {
      tree_.compute(p, field_, ctx.block_size, ctx.active);
    }
    stats_ = tree_.stats();
  }
  const std::size_t phi_field = p.add_field("potential", 1);
  Real* phi = p.extra(phi_field).data();
  const Real G = Real(options_.G);
  const bool unit = options_.G == 1;
  const ActiveSet& active = ctx.active;
  parallel::for_blocks("gravity_add", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    if (!active.all()) {  // block time steps: only the active particles' entries are this evaluation's
      for (std::size_t i = b; i < e; ++i) {
        if (!active.contains(i)) continue;
        for (int a = 0; a < 3; ++a) p.acceleration[a][i] += unit ? field_.acceleration[a][i] : G * field_.acceleration[a][i];
        phi[i] = unit ? field_.potential[i] : G * field_.potential[i];
      }
      return;
    }
    for (int a = 0; a < 3; ++a) {
      Real* acc = p.acceleration[a].data();
      const Real* add = field_.acceleration[a].data();
      if (unit) {  // N-body units: exactly the walk's values
#pragma omp simd
        for (std::size_t i = b; i < e; ++i) acc[i] += add[i];
      } else {
#pragma omp simd
        for (std::size_t i = b; i < e; ++i) acc[i] += G * add[i];
      }
    }
    for (std::size_t i = b; i < e; ++i) phi[i] = unit ? field_.potential[i] : G * field_.potential[i];
  });
  if (ctx.timers) {
    ctx.timers->add("forces.tree_build", stats_.tree_build_seconds);
    ctx.timers->add("forces.walk", stats_.force_seconds);
  }
  nodes_sum_ += stats_.mean_nodes_visited;
  ++evaluations_;
  particle_evaluations_ += double(stats_.walked);
  particles_ = p.size();
}

template <class Real>
void GravityForce<Real>::add_limits(const StepScan& scan, std::size_t n, std::vector<StepLimit>& out) const {
  const double accel = std::sqrt(scan.accel2);
  double length = settings_.softening;
  if (!(length > 0) && n > 1) {
    double extent = 0;
    for (int axis = 0; axis < 3; ++axis) extent = std::max(extent, scan.hi[axis] - scan.lo[axis]);
    length = extent / std::cbrt(static_cast<double>(n));
  }
  if (accel > 0 && length > 0)
    out.push_back({"gravity", options_.eta * std::sqrt(length / accel), scan.accel_at, accel, "|a|"});
}

template <class Real>
LimitText GravityForce<Real>::explain(const StepLimit& l, std::string_view id) const {
  return {fmt::format("the gravity condition η·sqrt({}/|a|max) with η = {} = {:.6g} (|a|max = {:.3g} at particle id {})",
                      settings_.softening > 0 ? "ε" : "d", options_.eta, l.dt, l.value, id),
          "or a larger softening ε"};
}

template <class Real>
void GravityForce<Real>::add_diagnostics(const ParticleSet<Real>& p, const dist::BlockFold& fold,
                                         std::vector<double>& row) const {
  row.insert(row.end(), {virial_ratio(p, fold), stats_.mean_nodes_visited});
}

template <class Real>
double GravityForce<Real>::potential_energy(const ParticleSet<Real>& p, const dist::BlockFold& fold) const {
  return gravity::potential_energy(p, fold);
}

template <class Real>
void GravityForce<Real>::add_metrics(NamedValues& out) const {
  out.emplace_back("mean_nodes_visited", evaluations_ > 0 ? nodes_sum_ / double(evaluations_) : stats_.mean_nodes_visited);
  out.emplace_back("particle_force_evaluations", particle_evaluations_);
  if (stats_.tree_bytes > 0 && particles_ > 0)
    out.emplace_back("tree_bytes_per_particle", double(stats_.tree_bytes) / double(particles_));
}

template <class Real>
std::size_t GravityForce<Real>::scratch_bytes() const {
  std::size_t whole = whole_.id.capacity() * sizeof(std::uint64_t) + whole_keys_.capacity() * sizeof(std::uint64_t) +
                      whole_active_.capacity() * sizeof(std::int32_t) + 4 * whole_field_.potential.capacity() * sizeof(Real);
  whole_.for_each_array([&](const AlignedVector<Real>& a) { whole += a.capacity() * sizeof(Real); });
  return stats_.tree_bytes + whole;
}

template <class Real>
void GravityForce<Real>::add_rank_metrics(NamedValues& out) const {
  // What the locally essential trees imported, per own particle (the export's volume);
  // the replicated methods (direct sum, FMM) import the whole set and build no essential tree.
  if (settings_.method != Method::BarnesHut) return;
  out.emplace_back("let_nodes_per_particle", own_particles_ > 0 ? imported_nodes_ / own_particles_ : 0.0);
  out.emplace_back("let_particles_per_particle", own_particles_ > 0 ? imported_particles_ / own_particles_ : 0.0);
}

template <class Real>
void GravityForce<Real>::save_state(NamedValues& out) const {
  out.emplace_back("self_gravity.nodes_sum", nodes_sum_);
  out.emplace_back("self_gravity.evaluations", double(evaluations_));
  out.emplace_back("self_gravity.particle_evaluations", particle_evaluations_);
}

template <class Real>
void GravityForce<Real>::load_state(const NamedValues& values) {
  nodes_sum_ = find_value(values, "self_gravity.nodes_sum").value_or(0.0);
  evaluations_ = static_cast<std::uint64_t>(find_value(values, "self_gravity.evaluations").value_or(0.0));
  particle_evaluations_ = find_value(values, "self_gravity.particle_evaluations").value_or(0.0);
}

template class GravityForce<float>;
template class GravityForce<double>;

}  // namespace swirl::gravity
