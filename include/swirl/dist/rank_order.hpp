// RankOrder: spatial::ParticleOrder across the ranks of a distributed run
// (docs/design/mpi.md; issue 19 items 2 and 5).
//
// Each rank holds a contiguous range [first, first + n) of the one global
// order, and the concatenation of the ranks' particles in rank order is the
// memory order a one-rank run has at the same step. update() keeps that
// invariant where ParticleOrder::update() sorts:
//   1. with a skin, the order is kept while no particle of any rank moved more
//      than keep_within (a max over ranks: exact);
//   2. the frame from the global bounding box (dist::global_key_frame: the
//      frame ParticleOrder would compute for all the particles), every
//      particle's key in it;
//   3. cut keys that split the particles' cost evenly (dist::balanced_cut_keys)
//      — a cost per particle of 1 plus the solvers' counts of its work in the
//      last evaluation (set_cost_rule: Solver::add_rank_costs, e.g. neighbour
//      candidates, interaction-list entries; integers, never timings) — kept
//      from the last sort while the imbalance they give (the largest rank's
//      cost over the mean) stays within the rebalance threshold, or while the
//      last evaluation measured no whole step (the rule returns false); then
//      distribute_in_key_order(): every
//      particle moves to the rank whose key range holds it, each rank's
//      particles sorted by (key, previous global index), which is the one-rank
//      stable sort whatever the rank count; a cut rule (set_cut_rule: the
//      solvers' Solver::rank_cuts) may move the cuts first, e.g. onto the
//      gravity tree's group boundaries.
// So keys(), frame() and the particles' order are the one-rank ones, cut into
// ranges; where the cuts fall changes no result (the halo's invariants,
// dist/halo.hpp), only the balance. A kept cut is a key of the last frame
// read in the new one (the frame follows the global box): still a valid
// partition, whose imbalance is measured before it is kept.
//
// adopt(): rank 0 builds (or reads from a checkpoint) the whole set and sends
// each rank its share (or every rank holds the whole set and keeps its share):
// an even slice of the memory order, or, for a
// checkpoint of a skin run whose reference positions are in sorted order, a
// slice whose ends fall between different keys, so that the kept order is
// valid at once and the next update() decides as the uninterrupted run would.
//
// Collective: adopt() and update() must be called by every rank. One rank
// (no MPI) is the trivial case and gives ParticleOrder's order and keys.
// Units: the positions' (m for SPH).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/dist/gather_particles.hpp"
#include "swirl/dist/halo.hpp"
#include "swirl/dist/key_cuts.hpp"
#include "swirl/dist/key_order.hpp"
#include "swirl/spatial/particle_order.hpp"

namespace swirl::dist {

template <class Real>
class RankOrder {
 public:
  explicit RankOrder(const Communicator& comm) : comm_(&comm) {}

  const Communicator& comm() const { return *comm_; }

  void set_request(const spatial::OrderRequest& request) {
    spatial::ParticleOrder<Real> check;  // the same validation and messages
    check.set_request(request);
    request_ = request;
  }
  const spatial::OrderRequest& request() const { return request_; }
  bool active() const { return request_.sorted; }

  // Moves the balanced cuts where the solvers need them (collective: every
  // rank gets this rank's keys and the same cuts, returns the same cuts).
  using CutRule = std::function<std::vector<std::uint64_t>(std::span<const std::uint64_t> keys,
                                                           std::vector<std::uint64_t> cuts)>;
  void set_cut_rule(CutRule rule) { cut_rule_ = std::move(rule); }

  // Adds each own particle's work in the last evaluation to costs (one per
  // particle, in the particles' current order; see the header) and returns
  // true; or returns false when the last evaluation did not measure a whole
  // step's work (block time steps' sub-steps evaluate only the active
  // particles): the cuts are then kept whatever their imbalance (an empty
  // rank still rebalances, by count) and rank_costs() stays the last measured.
  using CostRule = std::function<bool(std::span<std::uint64_t> costs)>;
  void set_cost_rule(CostRule rule) { cost_rule_ = std::move(rule); }
  // New cuts when the imbalance of the current ones passes this (≥ 1; 1:
  // new cuts at every sort).
  void set_rebalance_threshold(double threshold) {
    if (!(threshold >= 1) || !std::isfinite(threshold))
      throw std::invalid_argument("RankOrder: the rebalance threshold must be finite and ≥ 1");
    rebalance_threshold_ = threshold;
  }

  // p holds every particle in the one-rank memory order (a scene's initial
  // state, or a checkpoint's when resumed) — on every rank alike, or, with
  // whole_on_root, on rank 0 alone (the others' p without particles, with the
  // same fields: dist::share_layout_from_root), which sends each rank its
  // share: keeps this rank's share (see the header).
  void adopt(ParticleSet<Real>& p, bool resumed, bool whole_on_root = false) {
    const auto ranks = static_cast<std::size_t>(comm_->size()), r = static_cast<std::size_t>(comm_->rank());
    valid_ = false;
    balanced_ = false;
    keys_.clear();
    ++epoch_;
    // The plan every rank follows, made from the whole set: the count, the
    // slices' starts, the cuts, and for a skin run's sorted checkpoint the key
    // frame's box (bits of doubles).
    std::vector<std::uint64_t> plan;
    if (!whole_on_root || comm_->is_root()) plan = adoption_plan(p, resumed);
    if (whole_on_root && comm_->distributed()) {
      Bytes mine;
      if (comm_->is_root()) {
        mine.resize(plan.size() * sizeof(std::uint64_t));
        std::memcpy(mine.data(), plan.data(), mine.size());
      }
      const Bytes root = comm_->all_gather(mine)[0];
      plan.resize(root.size() / sizeof(std::uint64_t));
      std::memcpy(plan.data(), root.data(), root.size());
    }
    const std::size_t n = plan[0];
    const bool sorted_keys = plan[1] != 0;
    const std::vector<std::size_t> start(plan.begin() + 2, plan.begin() + 2 + static_cast<std::ptrdiff_t>(ranks + 1));
    cut_keys_.assign(plan.begin() + 3 + static_cast<std::ptrdiff_t>(ranks), plan.begin() + 2 + static_cast<std::ptrdiff_t>(2 * ranks));
    global_count_ = n;
    first_ = start[r];
    if (whole_on_root) scatter_from_root(*comm_, p, start);
    else keep_range(p, start[r], start[r + 1]);
    if (sorted_keys) {
      std::array<double, 3> lo{}, hi{};
      for (std::size_t a = 0; a < 3; ++a) {
        lo[a] = std::bit_cast<double>(plan[2 * ranks + 2 + a]);
        hi[a] = std::bit_cast<double>(plan[2 * ranks + 5 + a]);
      }
      bool fits = false;
      frame_ = spatial::ParticleOrder<Real>::frame_for(request_, lo, hi, fits);
      cells_fit_ = fits;
      const std::size_t ref = p.find_field(spatial::ParticleOrder<Real>::kReferenceField);
      keys_.resize(p.size());
      for (std::size_t i = 0; i < p.size(); ++i)
        keys_[i] = spatial::ParticleOrder<Real>::key_of(frame_, double(p.extra(ref, 0)[i]), double(p.extra(ref, 1)[i]),
                                                        double(p.extra(ref, 2)[i]));
      valid_ = true;
    }
  }

  // After particles were removed from or added to p (sim/inlets_outlets.hpp)
  // with the concatenation in rank order still the one-rank memory order:
  // where each rank's range starts and the count, and the next update()
  // sorts (as ParticleOrder::touch()). Collective.
  void particles_changed(const ParticleSet<Real>& p) {
    first_ = comm_->exclusive_prefix_sum(p.size());
    global_count_ = comm_->sum(std::uint64_t{p.size()});
    keys_.clear();
    valid_ = false;
    ++epoch_;
  }

  // Brings the particles into the global order when the request needs it
  // (see the header). Returns true when it sorted (on every rank alike).
  // Throws spatial::NonFinitePosition on every rank when any rank holds a
  // non-finite position.
  bool update(ParticleSet<Real>& p, std::size_t block_size) {
    if (!active()) return false;
    const bool skin = request_.keep_within > 0;
    if (skin && valid_ && keys_.size() == p.size() && within_tolerance(p)) return false;
    bool fits = false;
    frame_ = global_key_frame(*comm_, p, request_, fits, block_size);
    cells_fit_ = fits;
    keys_in_frame(frame_, p, keys_);
    costs_.assign(keys_.size(), 1);
    const bool measured = !cost_rule_ || cost_rule_(costs_);
    bool rebalance = !balanced_;
    std::vector<std::uint64_t> held;  // the cost each rank holds under the kept cuts
    if (!rebalance) {  // an empty rank (cost 0: every particle costs ≥ 1) always rebalances
      held = cost_per_rank(*comm_, keys_, costs_, cut_keys_);
      rebalance = std::find(held.begin(), held.end(), 0) != held.end() ||
                  (measured && dist::imbalance(held) > rebalance_threshold_);
    }
    if (rebalance) {
      cut_keys_ = balanced_cut_keys(*comm_, keys_, costs_);
      balanced_ = true;
      ++rebalances_;
    }
    if (cut_rule_) cut_keys_ = cut_rule_(keys_, std::move(cut_keys_));
    if (measured || rank_costs_.empty())  // `held` is for the cuts kept as they were
      rank_costs_ = !rebalance && !cut_rule_ ? std::move(held) : cost_per_rank(*comm_, keys_, costs_, cut_keys_);
    const Distribution d =
        distribute_in_key_order(*comm_, p, keys_, first_, cut_keys_, frame_.key_bits, distribute_work_);
    first_ = d.first_global_index;
    global_count_ = d.global_count;
    sent_away_ = d.sent_away;
    if (skin) remember(p, block_size);
    valid_ = true;
    ++epoch_;
    ++sorts_;
    return true;
  }

  // After update(): this rank's keys (sorted, one per own particle), the frame,
  // the cuts, and where the rank's range starts in the global order.
  std::span<const std::uint64_t> keys() const { return keys_; }
  const spatial::KeyFrame& frame() const { return frame_; }
  std::span<const std::uint64_t> cut_keys() const { return cut_keys_; }
  std::uint64_t first_global_index() const { return first_; }
  std::uint64_t global_count() const { return global_count_; }
  bool valid() const { return valid_; }
  bool cells_fit() const { return cells_fit_; }
  std::uint64_t epoch() const { return epoch_; }
  std::uint64_t sorts() const { return sorts_; }
  // Sorts that chose new cuts (the others kept the last ones).
  std::uint64_t rebalances() const { return rebalances_; }
  // The cost each rank's range held at the last sort, and its imbalance
  // (largest over mean; 1 before the first sort).
  std::span<const std::uint64_t> rank_costs() const { return rank_costs_; }
  double imbalance() const { return rank_costs_.empty() ? 1.0 : dist::imbalance(rank_costs_); }
  std::size_t sent_away() const { return sent_away_; }
  std::size_t bytes() const {
    // The kept sort buffers as ParticleOrder counts its own: keys and order, twice.
    return (keys_.capacity() + cut_keys_.capacity() + costs_.capacity() + rank_costs_.capacity()) * sizeof(std::uint64_t) +
           distribute_work_.reorder.bytes() + distribute_work_.destination.capacity() * sizeof(int) +
           (distribute_work_.source.capacity() + distribute_work_.picked.capacity()) * sizeof(std::uint32_t) +
           distribute_work_.unsorted.capacity() * sizeof(std::uint64_t) +
           keys_.size() * 2 * (sizeof(std::uint64_t) + sizeof(std::uint32_t));
  }

 private:
  // adopt()'s plan from the whole set p: {count, sorted keys (0/1), the
  // ranks' starts (size + 1), the cuts (size − 1), the frame box lo[3], hi[3]
  // as bits}. An even slice of the memory order each; for a skin run's
  // checkpoint whose reference positions are in sorted order, slices whose
  // ends fall between different keys, the cuts at those keys.
  std::vector<std::uint64_t> adoption_plan(const ParticleSet<Real>& p, bool resumed) const {
    const std::size_t n = p.size();
    const auto ranks = static_cast<std::size_t>(comm_->size());
    std::vector<std::size_t> start(ranks + 1, n);
    for (std::size_t k = 0; k < ranks; ++k) start[k] = n * k / ranks;
    std::vector<std::uint64_t> cuts(ranks - 1, 0);
    std::array<double, 3> lo{}, hi{};
    bool sorted_keys = false;
    const std::size_t ref = p.find_field(spatial::ParticleOrder<Real>::kReferenceField);
    if (resumed && active() && request_.keep_within > 0 && ref != ParticleSet<Real>::npos) {
      // The one-rank resume's keys: the reference positions' frame (ParticleOrder::resume).
      for (int a = 0; a < 3; ++a) {
        const auto& v = p.extra(ref, a);
        const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
        if (n > 0) lo[static_cast<std::size_t>(a)] = double(*mn), hi[static_cast<std::size_t>(a)] = double(*mx);
      }
      bool fits = false;
      const spatial::KeyFrame frame = spatial::ParticleOrder<Real>::frame_for(request_, lo, hi, fits);
      std::vector<std::uint64_t> all(n);
      for (std::size_t i = 0; i < n; ++i)
        all[i] = spatial::ParticleOrder<Real>::key_of(frame, double(p.extra(ref, 0)[i]), double(p.extra(ref, 1)[i]),
                                                      double(p.extra(ref, 2)[i]));
      if (std::is_sorted(all.begin(), all.end())) {
        // Slice ends at the first particle of a key, and the cuts at those keys.
        for (std::size_t k = 1; k < ranks; ++k) {
          if (start[k] < n) start[k] = static_cast<std::size_t>(std::lower_bound(all.begin(), all.end(), all[start[k]]) - all.begin());
          start[k] = std::max(start[k], start[k - 1]);
          cuts[k - 1] = start[k] < n ? all[start[k]] : std::numeric_limits<std::uint64_t>::max();
        }
        sorted_keys = true;
      }
    }
    std::vector<std::uint64_t> plan{n, sorted_keys ? 1u : 0u};
    plan.insert(plan.end(), start.begin(), start.end());
    plan.insert(plan.end(), cuts.begin(), cuts.end());
    for (const double v : lo) plan.push_back(std::bit_cast<std::uint64_t>(v));
    for (const double v : hi) plan.push_back(std::bit_cast<std::uint64_t>(v));
    return plan;
  }

  void remember(ParticleSet<Real>& p, std::size_t /*block_size*/) {
    const std::size_t ref = p.add_field(std::string(spatial::ParticleOrder<Real>::kReferenceField), 3, FieldUse::Internal);
    for (int a = 0; a < 3; ++a) std::copy(p.position[a].begin(), p.position[a].end(), p.extra(ref, a).begin());
  }

  // Whether no particle on any rank moved more than keep_within from its
  // reference position (in double, as ParticleOrder; a max: exact).
  bool within_tolerance(const ParticleSet<Real>& p) const {
    const std::size_t ref = p.find_field(spatial::ParticleOrder<Real>::kReferenceField);
    double worst[1] = {ref == ParticleSet<Real>::npos ? std::numeric_limits<double>::infinity() : 0.0};
    if (ref != ParticleSet<Real>::npos) {
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double dx = double(p.position.x[i]) - double(p.extra(ref, 0)[i]),
                     dy = double(p.position.y[i]) - double(p.extra(ref, 1)[i]),
                     dz = double(p.position.z[i]) - double(p.extra(ref, 2)[i]);
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (!(d2 <= worst[0])) worst[0] = d2 == d2 ? d2 : std::numeric_limits<double>::infinity();
      }
    }
    comm_->max(worst);
    const double tol = request_.keep_within;
    return worst[0] <= tol * tol;
  }

  const Communicator* comm_;
  spatial::OrderRequest request_;
  CutRule cut_rule_;
  CostRule cost_rule_;
  double rebalance_threshold_ = 1.05;
  bool balanced_ = false;  // cut_keys_ were balanced by a sort (adopt's are not)
  std::vector<std::uint64_t> costs_;       // per own particle, at the last sort (before it)
  std::vector<std::uint64_t> rank_costs_;  // per rank, at the last sort
  std::uint64_t rebalances_ = 0;
  spatial::KeyFrame frame_;
  bool cells_fit_ = true;
  bool valid_ = false;
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint64_t> cut_keys_;
  std::uint64_t first_ = 0;
  std::uint64_t global_count_ = 0;
  std::size_t sent_away_ = 0;
  std::uint64_t epoch_ = 0;
  std::uint64_t sorts_ = 0;
  DistributeWorkspace<Real> distribute_work_;  // the sort's buffers, kept between steps
};

// Compiled once, in src/dist/rank_order.cpp: users link the float and double copies
// instead of compiling them again.
extern template class RankOrder<float>;
extern template class RankOrder<double>;

}  // namespace swirl::dist
