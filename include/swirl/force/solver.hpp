// Solver<Real>: the seam through which physics enters a simulation.
//
// A solver is everything about one kind of physics: the SPH fluid, self-
// gravity, a uniform field, a drag. The simulation, the run loop and the CLI
// know solvers only through this interface, so a new kind of physics is one
// new class in its own module and nothing above it changes.
//
// What a solver owns:
//  - its fields: declare_fields() adds what it reads or writes beyond the
//    built-in ones (a potential: add_field; a particle kind or flag:
//    add_int_field), before the first step;
//  - its computation: add_acceleration() reads the state and ADDS into
//    particles.acceleration (the stepper zeroed it). It never permutes the
//    particles: the simulation owns the one particle order (a solver that
//    needs particles sorted by space asks for it with order_request() and
//    reads the order's keys from the context). It runs its loops through
//    parallel::for_blocks with ctx.block_size and gives bit-identical results
//    for any thread count; it throws with a message a user can act on. With
//    an active set in the context (block time steps) it must compute the
//    active particles and may skip the others (core/active_set.hpp);
//  - its time-step conditions: scan_needs() says what the step's scan must
//    measure; add_limits() turns the scan into StepLimits; explain() words a
//    limit for the blow-up guard, and advice() says what to change when the
//    state blows up;
//  - its diagnostics: columns and values of the per-frame log, its share of
//    the potential energy, and summary metrics;
//  - its state across a checkpoint (save_state/load_state): whatever changes
//    results or the reported figures and is not a particle field.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/core/active_set.hpp"
#include "swirl/core/named_values.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/dist/block_fold.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/force/step_scan.hpp"
#include "swirl/spatial/particle_order.hpp"

namespace swirl {

namespace dist {
template <class Real>
class RankOrder;
}  // namespace dist

// What a solver may know about the evaluation it is called in.
template <class Real>
struct SolverContext {
  double time = 0;                                      // simulated time of the positions
  std::size_t block_size = 1;                           // work-block size for parallel passes
  PhaseTimers* timers = nullptr;                        // where a solver may time its sub-phases
  const spatial::ParticleOrder<Real>* order = nullptr;  // the particle order, current for these positions
  ActiveSet active;  // the particles to compute (block time steps); others' acceleration may be left as is
  // On several ranks (dist/rank_order.hpp): the global order this rank's
  // particles are a range of (order is then null). A solver that does not run
  // on ranks throws std::invalid_argument; the run refuses such scenes first.
  const dist::RankOrder<Real>* ranks = nullptr;
};

// A limit's words for the guard: the rule with its numbers, and the change that relaxes it.
struct LimitText {
  std::string rule;  // e.g. "the CFL condition C_cfl·h/(c + |v|max) = 0.6·0.02/(20 + 3.1) = 0.00052"
  std::string fix;   // e.g. "or a larger smoothing length h"
};

template <class Real>
class Solver {
 public:
  virtual ~Solver() = default;

  // A short name for summaries, phases and messages, e.g. "sph".
  virtual std::string_view name() const = 0;

  // Adds the fields this solver needs (ParticleSet::add_field,
  // add_int_field); called once before the first evaluation and again after a
  // checkpoint is read.
  virtual void declare_fields(ParticleSet<Real>& /*particles*/) {}

  // The particle order this solver needs (none by default).
  virtual spatial::OrderRequest order_request() const { return {}; }

  // Adds this solver's acceleration into particles.acceleration (see the header).
  virtual void add_acceleration(ParticleSet<Real>& particles, const SolverContext<Real>& ctx) = 0;

  // On several ranks: where the ranks' key ranges may end. Given this rank's
  // keys (dist::RankOrder's, this evaluation's) and cuts balanced by cost,
  // returns the cuts this solver's passes need (self-gravity: on group
  // boundaries of the global tree). Collective; the same cuts on every rank.
  virtual std::vector<std::uint64_t> rank_cuts(const dist::Communicator& /*comm*/,
                                               std::span<const std::uint64_t> /*keys*/,
                                               std::vector<std::uint64_t> cuts) const {
    return cuts;
  }

  // On several ranks: adds to costs (one per particle of this rank, in the
  // particles' current order) each particle's work in this solver's last
  // evaluation, as an integer count of the same kind for every particle
  // (neighbour candidates, interaction-list entries): what dist::RankOrder
  // balances the ranks by. Never a timing, so that a run decides the same
  // cuts every time. Adds nothing when the solver has no evaluation of these
  // particles yet (e.g. right after a resume).
  virtual void add_rank_costs(std::span<std::uint64_t> /*costs*/) const {}

  // Time-step conditions.
  virtual ScanNeeds scan_needs() const { return {}; }
  // Appends this solver's limits for a scanned state of `n` particles.
  virtual void add_limits(const StepScan& /*scan*/, std::size_t /*n*/, std::vector<StepLimit>& /*out*/) const {}
  // Words for one of its own limits; `particle` is the id (or "?").
  virtual LimitText explain(const StepLimit& limit, std::string_view particle) const {
    return {std::string(limit.condition) + " condition (particle id " + std::string(particle) + ")", ""};
  }
  // What to change when the state blows up, e.g. "for close encounters, a larger softening".
  virtual std::string advice() const { return {}; }

  // Diagnostics: the solver's columns of the per-frame log and their values,
  // over `particles` (this rank's own; on one rank the whole set), whose
  // place in the one-rank order `fold` says: sums and maxima over them go
  // through fold (dist/block_fold.hpp), so the values have the one-rank bits
  // on any rank count. Collective on ranks: every rank calls, every rank gets
  // the values.
  virtual std::vector<std::string> diagnostic_columns() const { return {}; }
  virtual void add_diagnostics(const ParticleSet<Real>& /*particles*/, const dist::BlockFold& /*fold*/,
                               std::vector<double>& /*row*/) const {}
  // Its potential energy in the current state (0 for forces without one), the same way.
  virtual double potential_energy(const ParticleSet<Real>& /*particles*/, const dist::BlockFold& /*fold*/) const {
    return 0;
  }
  // False when the solver dissipates or stores energy the log does not count
  // (then a total-energy error means nothing and is not reported).
  virtual bool conserves_energy() const { return true; }
  // Summary figures over the run so far, e.g. {"mean_neighbours", 24.9}.
  virtual void add_metrics(NamedValues& /*out*/) const {}
  // On several ranks: this rank's own figures over the run so far, e.g.
  // {"halo_ghosts_per_particle", 0.13}; the run reports each as its mean and
  // its largest value over the ranks (every rank must add the same names).
  virtual void add_rank_metrics(NamedValues& /*out*/) const {}
  // Bytes the solver keeps between evaluations (search structures, scratch).
  virtual std::size_t scratch_bytes() const { return 0; }

  // State across a checkpoint: names prefixed with name() + ".".
  virtual void save_state(NamedValues& /*out*/) const {}
  virtual void load_state(const NamedValues& /*values*/) {}
};

// Evaluates one solver on its own (tests, benchmarks, tools): declares its
// fields, brings the particles into the order it asks for (through `order`,
// which keeps its state between calls, e.g. a skin) and adds its acceleration.
// Inside a simulation the Simulation does this for all solvers at once.
template <class Real>
void evaluate_alone(Solver<Real>& solver, ParticleSet<Real>& particles, spatial::ParticleOrder<Real>& order,
                    std::size_t block_size, PhaseTimers* timers = nullptr, double time = 0) {
  solver.declare_fields(particles);
  order.set_request(solver.order_request());
  order.update(particles, block_size);
  solver.add_acceleration(particles, SolverContext<Real>{time, block_size, timers, order.active() ? &order : nullptr, {}, nullptr});
}

// The same with an order made for this one call (no skin carried over).
template <class Real>
void evaluate_alone(Solver<Real>& solver, ParticleSet<Real>& particles, std::size_t block_size) {
  spatial::ParticleOrder<Real> order;
  evaluate_alone(solver, particles, order, block_size);
}

// Compiled once, in src/force/solver.cpp: users link the float and double copies
// instead of compiling them again.
extern template class Solver<float>;
extern template class Solver<double>;

}  // namespace swirl
