// Simulation<Real>: the particles, their one order in memory, the solvers, the
// stepper and the time-step controller with its guard. It names no solver and
// no method: physics comes in through force/solver.hpp, time integration
// through integrate/stepper.hpp.
//
// One step:
//   Δt       fixed, or adaptive: min(the solvers' tightest limit, dt_max,
//            growth × the previous choice), shortened to land on a requested time
//   stepper  its updates around forces.evaluate(t), which
//              1. zeroes a,
//              2. brings the particles into the shared order when a solver
//                 asked for one (spatial/particle_order.hpp: one sort and one
//                 reorder of every field, or none while a skin allows),
//              3. lets every solver add its acceleration, in the order added;
//   scan     fused into the stepper's last pass: non-finite fields and the
//            extremes the solvers' conditions need;
//   guard    a non-finite state throws SimulationError; a particle that left
//            the box, a fixed Δt beyond a condition or a collapsed adaptive Δt
//            throws too, or (OnBlowUp::Warn) is reported through take_events().
//            Checks made outside the step (the run's energy error) go through
//            fail_check() and obey the same policy.
// start() refuses initial forces that are not finite (two particles on one
// spot without softening): no step is to blame, so the message says so.
// Messages name the step, the time, the particle id, the quantity, and the fix
// the solvers advise.
//
// Determinism: every pass runs over fixed blocks and writes only its own
// block; reductions fold in block order; so the state is bit-identical for any
// thread count. With a fixed Δt, time is step·Δt, never accumulated.
//
// Adaptive steps keep velocity Verlet's second order (Δt_n is a smooth function
// of the state with bounded growth) but lose exact time symmetry, so long
// orbits' energy errors can drift instead of staying bounded; gravity runs that
// need a bounded error keep a fixed Δt (docs/stability.md).
//
// Several ranks (distribute(), issue 19; docs/design/mpi.md): rank 0 builds
// (or reads) the whole set and sends each rank its range of the global order
// (or every rank holds the whole set and keeps its range)
// (dist/rank_order.hpp) and steps only its own particles; the solvers get the
// rank order in their context in place of the one-rank order (SPH exchanges
// ghosts). Whatever decides the run's course is global and exact: the scan is
// each rank's block-order fold, with global indices, folded again in rank
// order (the one-rank fold's result); the limits count all particles; a
// failed check is found on every rank at once, and its message (a particle's
// fields) comes from the rank that holds the particle. whole_particles()
// gathers the one-rank memory order on rank 0 for frames and checkpoints.
// So every rank count gives the one-rank bits.
//
// Moving obstacles (set_moving_boundaries(), boundary/moving_boundaries.hpp):
// before every force evaluation at time t, and so before the order's sort,
// their boundary particles are put at the prescribed motion's position and
// velocity for t; their acceleration is zeroed as every boundary particle's.
// They hold no state of their own (the motion is a function of t). On several
// ranks each rank holds the whole rest table, keyed by id, and places the
// particles it holds: a particle's place depends on its id and t alone, so
// where the cuts fall changes nothing.
//
// Checkpoints: save_state()/resume() carry the clock, the controller, the
// stepper's and every solver's state; the particle fields (including the
// order's reference positions when a skin is used) travel in the checkpoint's
// field section. A resumed run is bit-identical to one that never stopped.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "swirl/boundary/box_collision.hpp"
#include "swirl/boundary/moving_boundaries.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/core/named_values.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/dist/gather_particles.hpp"
#include "swirl/dist/rank_order.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/force/step_scan.hpp"
#include "swirl/integrate/kick_drift.hpp"
#include "swirl/integrate/stepper.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/blow_up.hpp"
#include "swirl/spatial/particle_order.hpp"

namespace swirl {

struct SimulationSettings {
  double dt = 0;                  // the time step (> 0); adaptive: the largest step (dt_max)
  std::size_t block_size = 1024;  // particles per work block (≥ 1)
  // Walls for the default stepper (velocity Verlet with the thesis's box); none
  // = open space. Ignored when a stepper is given to the constructor.
  std::optional<boundary::BoxCollision<double>> box;
  bool adaptive = false;          // choose Δt from the solvers' limits before every step
  double dt_min = 0;              // adaptive: a smaller Δt is a blow-up; 0: 1e-6 × the first step's
  double growth = 1.25;           // adaptive: Δt grows at most by this factor per step (> 1)
  // With a box: a particle further than this outside after a position update
  // has left the domain (scenes set the SPH kernel support h); 0: no check.
  double escape_length = 0;
  OnBlowUp on_blow_up = OnBlowUp::Stop;
  // Several ranks: new cuts when the ranks' cost imbalance passes this (≥ 1; dist/rank_order.hpp).
  double rebalance_threshold = 1.05;
};

// Where a run is in time, and the adaptive controller's memory.
struct SimulationClock {
  std::uint64_t step = 0;
  double time = 0;         // adaptive: the time reached (fixed Δt: step·Δt)
  double previous_dt = 0;  // adaptive: the previous unshortened choice (0 before the first step)
  double dt_floor = 0;     // adaptive: the collapse floor, fixed at the first step
};

template <class Real>
class Simulation {
 public:
  Simulation(ParticleSet<Real> particles, SimulationSettings settings,
             std::unique_ptr<integrate::Stepper<Real>> stepper = nullptr)
      : particles_(std::move(particles)), settings_(std::move(settings)), stepper_(std::move(stepper)) {
    if (!(settings_.dt > 0) || !std::isfinite(settings_.dt)) throw std::invalid_argument("dt must be finite and > 0");
    if (settings_.block_size == 0) throw std::invalid_argument("block_size must be at least 1");
    if (settings_.adaptive && !(settings_.growth > 1)) throw std::invalid_argument("growth must be > 1");
    if (!(settings_.dt_min >= 0) || !(settings_.escape_length >= 0))
      throw std::invalid_argument("dt_min and escape_length must be >= 0");
    if (!stepper_) {
      std::optional<boundary::BoxCollision<Real>> box;
      if (settings_.box) box = boundary::BoxCollision<Real>{settings_.box->box.template cast<Real>(), Real(settings_.box->restitution)};
      stepper_ = std::make_unique<integrate::KickDriftStepper<Real>>(integrate::Method::VelocityVerlet, std::move(box));
    }
  }

  // Runs on the ranks of comm (a no-op on one rank): call before start() or
  // resume(), with the whole set in particles() on every rank; start() or
  // resume() then keeps this rank's share (see the header). With
  // whole_on_root: only rank 0's particles() hold the set; the others' none,
  // with the same fields (dist::share_layout_from_root); start() or resume()
  // then sends each rank its share.
  void distribute(const dist::Communicator& comm, bool whole_on_root = false) {
    if (started_) throw std::logic_error("Simulation::distribute() after start()");
    whole_on_root_ = whole_on_root;
    if (comm.distributed()) {
      ranks_ = std::make_unique<dist::RankOrder<Real>>(comm);
      ranks_->set_rebalance_threshold(settings_.rebalance_threshold);
    }
  }
  // Obstacles whose boundary particles follow a prescribed motion. Before
  // start() or resume(). On several ranks every rank holds the same whole
  // table (by id): each places the moving particles it holds.
  void set_moving_boundaries(std::shared_ptr<const boundary::MovingBoundaries> moving) {
    if (started_) throw std::logic_error("Simulation::set_moving_boundaries() after start()");
    moving_ = std::move(moving);
  }
  const boundary::MovingBoundaries* moving_boundaries() const { return moving_.get(); }

  // The rank order on several ranks, or null.
  const dist::RankOrder<Real>* ranks() const { return ranks_.get(); }
  // Particles in the whole run (this rank's on one rank).
  std::uint64_t global_count() const { return ranks_ ? ranks_->global_count() : particles_.size(); }

  // The whole state in the one-rank memory order, for frames and checkpoints.
  // Collective on several ranks: there rank 0 gets every particle (gathered
  // once per step and order, and freed when the next step starts: rank 0
  // holds a second copy of the whole set only while the writers of a step
  // use it) and the other ranks an empty set.
  const ParticleSet<Real>& whole_particles() const {
    if (!ranks_) return particles_;
    const auto stamp = std::make_pair(clock_.step, epoch());
    if (!gathered_valid_ || gathered_stamp_ != stamp) {
      gathered_ = dist::gather_to_root(ranks_->comm(), particles_);
      gathered_stamp_ = stamp;
      gathered_valid_ = true;
    }
    return gathered_;
  }

  // What a failed check does from now on (the settings' on_blow_up until then).
  void set_on_blow_up(OnBlowUp policy) { settings_.on_blow_up = policy; }

  // Adds a solver; solvers add their accelerations in the order added. Before start().
  void add_solver(std::unique_ptr<Solver<Real>> solver) {
    if (prepared_) throw std::logic_error("Simulation::add_solver() after start() or prepare()");
    solvers_.push_back(std::move(solver));
  }

  // Declares every field the stepper, the solvers and the order use, and fixes
  // the order's request. start() and resume() call it; call it yourself before
  // reading a checkpoint into particles(), so that the file's fields meet
  // their declared uses.
  void prepare() {
    if (prepared_) return;
    spatial::OrderRequest request;
    needs_ = {};
    stepper_->declare_fields(particles_);
    for (auto& s : solvers_) {
      s->declare_fields(particles_);
      request = spatial::OrderRequest::combine(request, s->order_request());
      needs_ |= s->scan_needs();
    }
    order_.set_request(request);
    if (ranks_) {
      ranks_->set_request(request);
      ranks_->set_cut_rule([this](std::span<const std::uint64_t> keys, std::vector<std::uint64_t> cuts) {
        for (const auto& s : solvers_) cuts = s->rank_cuts(ranks_->comm(), keys, std::move(cuts));
        return cuts;
      });
      ranks_->set_cost_rule([this](std::span<std::uint64_t> costs) { return add_rank_costs(costs); });
    }
    if (request.keep_within > 0) particles_.add_field(std::string(spatial::ParticleOrder<Real>::kReferenceField), 3, FieldUse::Internal);
    prepared_ = true;
  }

  // Computes a₀ = F(x₀) (and whatever the stepper keeps). Call once before the first step().
  void start() {
    prepare();
    if (ranks_) ranks_->adopt(particles_, false, whole_on_root_);
    Evaluation forces(*this);
    stepper_->start(particles_, forces, time(), settings_.block_size);
    rescan();
    if (scan_.non_finite != kNoParticle) throw_non_finite(scan_.non_finite);
    started_ = true;
  }

  // A solver's parameter was changed between steps (swirl view's sliders:
  // SphFluid::set_viscosity, ...): finds again what the step's scan gathers
  // (a viscosity turned on needs the density extremes) and the limits of the
  // current state, so that the next Δt and the guard follow the new value.
  void parameters_changed() {
    if (!prepared_) return;
    needs_ = {};
    for (auto& s : solvers_) needs_ |= s->scan_needs();
    if (started_) rescan();
  }

  // Continues from a restored state instead of start(): particles() holds
  // every field as it was after clock.step (a checkpoint), `state` what
  // save_state() wrote then; the next step() is the one the original run took.
  void resume(const SimulationClock& clock, const NamedValues& state = {}) {
    prepare();
    clock_ = clock;
    stepper_->load_state(state);
    for (auto& s : solvers_) s->load_state(state);
    if (ranks_)
      ranks_->adopt(particles_, true, whole_on_root_);
    else
      order_.resume(particles_, settings_.block_size);
    rescan();  // the limits are a function of the restored fields: the same as before the stop
    started_ = true;
  }

  // Changes the particles between steps (inlets and outlets,
  // sim/inlets_outlets.hpp): edit(particles()) may remove particles
  // (ParticleSet::remove_if) and add new ones at the end (resize), with their
  // position, velocity, mass, id and kind set and every other field zero.
  // The state is then made whole again as start() makes it: the order is redone
  // (the epoch changes), the stepper's start() evaluates the forces at the
  // current positions (new particles get their acceleration, the fluid its
  // density and DFSPH factor; a resumed run re-evaluates the same state), and
  // the limits follow the new state. Serial edits and the usual passes: the
  // same bits for any thread count. On several ranks every rank calls it (the
  // edit of its own particles; new ones only on the last rank, so that the
  // concatenation stays the one-rank memory order): the same bits for any
  // rank count.
  template <class Edit>
  void change_particles(Edit&& edit) {
    if (!started_) throw std::logic_error("Simulation::change_particles() before start()");
    edit(particles_);
    order_.touch();
    if (ranks_) ranks_->particles_changed(particles_);
    gathered_valid_ = false;
    Evaluation forces(*this);
    stepper_->start(particles_, forces, time(), settings_.block_size);
    rescan();
    if (scan_.non_finite != kNoParticle) throw_non_finite(scan_.non_finite);
  }

  // The state beyond the particle fields that resume() needs (with clock()).
  void save_state(NamedValues& out) const {
    stepper_->save_state(out);
    for (const auto& s : solvers_) s->save_state(out);
  }

  // Advances the state by one time step (see the header comment). Adaptive
  // runs shorten the step so that it ends exactly at land_at if it would pass it.
  void step(std::optional<double> land_at = {}) {
    if (!started_) throw std::logic_error("Simulation::step() before start()");
    // Rank 0's gathered copy of the whole set served this step's writers: free it.
    if (gathered_valid_) gathered_ = ParticleSet<Real>(), gathered_valid_ = false;
    double dt_step = settings_.dt, t_next = time_of(clock_.step + 1);
    if (settings_.adaptive) {
      const double proposal = proposed_dt();
      if (clock_.dt_floor == 0) clock_.dt_floor = settings_.dt_min > 0 ? settings_.dt_min : 1e-6 * proposal;
      if (proposal < clock_.dt_floor) throw_collapse(proposal);
      dt_step = proposal;
      t_next = clock_.time + dt_step;
      if (land_at && *land_at > clock_.time) {
        const double remaining = *land_at - clock_.time;
        // Within rounding of the choice, land (a step 1e-9 longer is no risk; two half steps would waste one).
        if (remaining <= dt_step * (1 + 1e-9)) {
          dt_step = remaining, t_next = *land_at;
        } else if (2 * dt_step > remaining) {
          dt_step = remaining / 2, t_next = clock_.time + dt_step;  // two equal steps, not one long and a sliver
        }
      }
      clock_.previous_dt = proposal;
    }
    const bool checks = settings_.on_blow_up != OnBlowUp::Off;
    integrate::StepRequest request;
    request.dt = dt_step;
    request.t_next = t_next;
    request.block_size = settings_.block_size;
    request.scan = checks || settings_.adaptive;
    request.needs = needs_;
    request.escape_length = checks ? settings_.escape_length : 0;
    request.timers = &timers_;
    request.ranks = ranks_ ? &ranks_->comm() : nullptr;
    Evaluation forces(*this);
    const integrate::StepOutcome outcome = stepper_->advance(particles_, forces, request);
    scan_ = global_scan(outcome.scan);
    const integrate::Escape escape = global_escape(outcome.escape);
    ++clock_.step;
    clock_.time = t_next;
    last_dt_ = dt_step;
    evaluate_limits();
    if (scan_.non_finite != kNoParticle) throw_non_finite(scan_.non_finite);
    if (!checks) return;
    if (escape.found) report(BlowUpCause::LeftDomain, escape_message(escape));
    if (!outcome.not_converged.empty())
      report(BlowUpCause::NotConverged, fmt::format("{}: blow-up: {}", where(), outcome.not_converged));
    const StepLimit& tight = tightest();
    if (outcome.finest_dt > 0) {  // divided steps: the finest sub-step against the tightest limit
      if (outcome.finest_dt > tight.dt * (1 + 1e-12))
        report(BlowUpCause::TimeStep, condition_message(tight, outcome.finest_dt, outcome.finest_fix));
    } else if (!settings_.adaptive && settings_.dt > tight.dt) {
      report(BlowUpCause::TimeStep, condition_message(tight, settings_.dt, "or dt = \"adaptive\""));
    }
  }

  // The step the next step() takes before any landing: the fixed Δt, or the
  // adaptive choice min(tightest limit, dt_max, growth × previous choice).
  double proposed_dt() const {
    if (!settings_.adaptive) return settings_.dt;
    double dt = std::min(tightest().dt, settings_.dt);
    if (clock_.previous_dt > 0) dt = std::min(dt, settings_.growth * clock_.previous_dt);
    return dt;
  }

  double time() const { return settings_.adaptive ? clock_.time : time_of(clock_.step); }
  std::uint64_t step_count() const { return clock_.step; }
  // The clock to save in a checkpoint (time filled in for fixed steps too).
  SimulationClock clock() const {
    SimulationClock c = clock_;
    c.time = time();
    return c;
  }
  double last_dt() const { return last_dt_; }  // the step last taken (0 before the first)
  // Every solver's limits of the current state, and the tightest (dt = ∞ when none).
  const std::vector<StepLimit>& limits() const { return limits_; }
  const StepLimit& tightest() const {
    static const StepLimit kNone{};
    const StepLimit* best = &kNone;
    for (const auto& l : limits_)
      if (l.dt < best->dt) best = &l;
    return *best;
  }
  const StepScan& scan() const { return scan_; }
  // A check made outside step() failed (e.g. the run's energy error): with
  // OnBlowUp::Stop throws SimulationError "<where>: blow-up: <problem>; fix: ...",
  // with Warn records it for take_events(), with Off does nothing.
  void fail_check(BlowUpCause cause, std::string_view problem) {
    if (settings_.on_blow_up == OnBlowUp::Off) return;
    report(cause, fmt::format("{}: blow-up: {}; {}", where(), problem, fix_for_dt(suggested_dt())));
  }
  // Failed checks of OnBlowUp::Warn since the last call.
  std::vector<GuardEvent> take_events() { return std::exchange(events_, {}); }
  const SimulationSettings& settings() const { return settings_; }
  const ParticleSet<Real>& particles() const { return particles_; }
  ParticleSet<Real>& particles() { return particles_; }
  const spatial::ParticleOrder<Real>& order() const { return order_; }
  // Changes whenever the particles' memory order or count may have changed.
  std::uint64_t epoch() const { return order_.epoch() + (ranks_ ? ranks_->epoch() + evaluations_on_ranks_ : 0); }
  PhaseTimers& timers() { return timers_; }
  const PhaseTimers& timers() const { return timers_; }
  const std::vector<std::unique_ptr<Solver<Real>>>& solvers() const { return solvers_; }
  // The first solver of type S, or null: for tools that report one kind's own
  // figures (the run loop never asks).
  template <class S>
  const S* find_solver() const {
    for (const auto& s : solvers_)
      if (const auto* found = dynamic_cast<const S*>(s.get())) return found;
    return nullptr;
  }
  const integrate::Stepper<Real>& stepper() const { return *stepper_; }

 private:
  // The force evaluation the stepper calls.
  class Evaluation final : public integrate::Forces {
   public:
    explicit Evaluation(Simulation& sim) : sim_(sim) {}
    void evaluate(double t) override { sim_.compute_forces(t, 0); }
    void evaluate_active(double t, std::int32_t min_bin) override { sim_.compute_forces(t, min_bin); }

   private:
    Simulation& sim_;
  };

  double time_of(std::uint64_t step) const { return static_cast<double>(step) * settings_.dt; }

  // a ← F(x) at time t, for every particle or (min_bin > 0) for those whose
  // time bin is at least min_bin (the field is found after the order's sort).
  void compute_forces(double t, std::int32_t min_bin) {
    ScopedPhase phase(timers_, "forces");
    parallel::for_blocks_pinned("zero_acceleration", particles_.size(), settings_.block_size,
                                [&](std::size_t b, std::size_t e, std::size_t) {
                                  for (int axis = 0; axis < 3; ++axis) {
                                    Real* a = particles_.acceleration[axis].data();
#pragma omp simd
                                    for (std::size_t i = b; i < e; ++i) a[i] = Real(0);
                                  }
                                });
    // Moving obstacles to their place at t, before the order looks at positions.
    if (moving_) moving_->apply(particles_, t, settings_.block_size);
    if (ranks_) {
      ++evaluations_on_ranks_;  // the SPH ghosts come and go: buffers may move
      ScopedPhase sort(timers_, "forces.sort");
      try {
        ranks_->update(particles_, settings_.block_size);
      } catch (const spatial::NonFinitePosition&) {  // thrown on every rank alike
        throw_non_finite(first_non_finite_position());
      }
    } else if (order_.active()) {
      ScopedPhase sort(timers_, "forces.sort");
      // A position the drift made non-finite stops the sort; it is a blow-up
      // of the state (exit 1, the particle named), not bad input. The search
      // for the particle runs only then: the sort's bounds pass already checks.
      try {
        order_.update(particles_, settings_.block_size);
      } catch (const spatial::NonFinitePosition&) {
        throw_non_finite(first_non_finite_position());
      }
    }
    SolverContext<Real> ctx{t, settings_.block_size, &timers_, order_.active() && !ranks_ ? &order_ : nullptr, {},
                            ranks_.get()};
    last_evaluation_partial_ = min_bin > 0;
    if (min_bin > 0) {
      const std::size_t bins = particles_.find_int_field(integrate::kTimeBinField);
      if (bins == ParticleSet<Real>::npos) throw std::logic_error("Simulation: an active evaluation without time bins");
      ctx.active = ActiveSet{particles_.int_field(bins).data(), min_bin};
    }
    for (auto& s : solvers_) s->add_acceleration(particles_, ctx);
    hold_boundary_particles();
  }

  // The cost rule of the cuts (dist::RankOrder::set_cost_rule): the solvers'
  // counts of each particle's work in the last evaluation. With time bins
  // (block time steps) a particle in bin k is evaluated 2^k times a step, so
  // its work counts 2^min(k, 16) times (the cap keeps the sums of 10^8
  // particles within 64 bits); an evaluation of the active particles only
  // measured no whole step: false, the cuts are kept.
  bool add_rank_costs(std::span<std::uint64_t> costs) {
    if (last_evaluation_partial_) return false;
    const std::size_t k = particles_.find_int_field(integrate::kTimeBinField);
    if (k == ParticleSet<Real>::npos || costs.size() != particles_.size()) {
      for (const auto& s : solvers_) s->add_rank_costs(costs);
      return true;
    }
    rank_work_.assign(costs.size(), 0);
    for (const auto& s : solvers_) s->add_rank_costs(rank_work_);
    const std::int32_t* bin = particles_.int_field(k).data();
    for (std::size_t i = 0; i < costs.size(); ++i) costs[i] += rank_work_[i] << std::clamp(bin[i], 0, 16);
    return true;
  }

  // Boundary particles (core/particle_kind.hpp) are not integrated: their
  // acceleration is zeroed after every evaluation (gravity and the fluid's
  // reaction included), so that with v = 0 the steppers leave a static one in
  // place (a moving one is put at its place by the next evaluation).
  void hold_boundary_particles() {
    const std::size_t k = particles_.find_int_field(kKindField);
    if (k == ParticleSet<Real>::npos) return;
    const std::int32_t* kind = particles_.int_field(k).data();
    parallel::for_blocks_pinned("hold_boundary", particles_.size(), settings_.block_size,
                                [&](std::size_t b, std::size_t e, std::size_t) {
                                  for (int axis = 0; axis < 3; ++axis) {
                                    Real* a = particles_.acceleration[axis].data();
#pragma omp simd
                                    for (std::size_t i = b; i < e; ++i) a[i] = is_boundary(kind[i]) ? Real(0) : a[i];
                                  }
                                });
  }

  // The first particle whose position is not finite (the order found one);
  // on ranks its global index (collective).
  std::size_t first_non_finite_position() const {
    std::size_t found = kNoParticle;
    for (std::size_t i = 0; i < particles_.size(); ++i)
      if (!std::isfinite(particles_.position.x[i]) || !std::isfinite(particles_.position.y[i]) ||
          !std::isfinite(particles_.position.z[i])) {
        found = i;
        break;
      }
    if (!ranks_) return found == kNoParticle ? 0 : found;
    double first[1] = {found == kNoParticle ? std::numeric_limits<double>::infinity()
                                            : double(ranks_->first_global_index() + found)};
    ranks_->comm().min(first);
    return std::isfinite(first[0]) ? static_cast<std::size_t>(first[0]) : 0;
  }

  // On ranks: the step's scan of every rank (block-order folds, indices made
  // global) folded in rank order, on every rank: the one-rank fold.
  StepScan global_scan(StepScan mine) const {
    if (!ranks_) return mine;
    const std::size_t first = ranks_->first_global_index();
    for (std::size_t* index : {&mine.non_finite, &mine.speed_at, &mine.accel_at, &mine.density_at})
      if (*index != kNoParticle) *index += first;
    StepScan all;
    for (const dist::Bytes& b : ranks_->comm().all_gather(to_bytes(mine))) all = StepScan::combine(all, from_bytes<StepScan>(b));
    return all;
  }
  // The same for the drift's escape (the largest excess, the first on ties).
  integrate::Escape global_escape(const integrate::Escape& mine) const {
    if (!ranks_) return mine;
    integrate::Escape all;
    for (const dist::Bytes& b : ranks_->comm().all_gather(to_bytes(mine))) {
      const auto e = from_bytes<integrate::Escape>(b);
      if (e.excess > all.excess) all = e;
    }
    return all;
  }
  template <class T>
  static dist::Bytes to_bytes(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    dist::Bytes b(sizeof(T));
    std::memcpy(b.data(), &value, sizeof(T));
    return b;
  }
  template <class T>
  static T from_bytes(const dist::Bytes& b) {
    T value{};
    if (b.size() != sizeof(T)) throw std::runtime_error("Simulation: a rank sent a record of the wrong size");
    std::memcpy(&value, b.data(), sizeof(T));
    return value;
  }
  // On ranks: text that the rank holding global particle `index` makes
  // (make(local index)), on every rank (collective).
  template <class Make>
  std::string from_owner(std::size_t index, Make&& make) const {
    const std::uint64_t first = ranks_->first_global_index();
    std::string mine;
    if (index >= first && index < first + particles_.size()) mine = make(static_cast<std::size_t>(index - first));
    std::string text = ranks_->comm().first_text(mine);
    return text.empty() ? "?" : text;
  }

  void evaluate_limits() {
    limits_.clear();
    for (std::size_t k = 0; k < solvers_.size(); ++k) {
      const std::size_t first = limits_.size();
      solvers_[k]->add_limits(scan_, global_count(), limits_);
      for (std::size_t j = first; j < limits_.size(); ++j) limits_[j].source = k;
    }
  }

  // The scan of the current state outside a step (start, resume).
  void rescan() {
    scan_ = parallel::reduce_blocks_pinned(
        "scan", particles_.size(), settings_.block_size, StepScan{},
        [&](std::size_t b, std::size_t e) { return scan_block(particles_, b, e, needs_); }, &StepScan::combine);
    scan_ = global_scan(scan_);
    evaluate_limits();
  }

  // "step 12 (t = 0.0048)": where a message happened.
  std::string where() const { return fmt::format("step {} (t = {:.6g})", clock_.step, time()); }

  // The id of particle `index` (global on ranks: collective).
  std::string particle_id(std::size_t index) const {
    if (ranks_) return from_owner(index, [&](std::size_t i) { return std::to_string(particles_.id[i]); });
    return index < particles_.size() ? std::to_string(particles_.id[index]) : std::string("?");
  }

  // The solvers' advice, or a generic one.
  std::string advice() const {
    std::string out;
    for (const auto& s : solvers_) {
      const std::string a = s->advice();
      if (!a.empty()) out += (out.empty() ? "" : "; ") + a;
    }
    return out.empty() ? std::string("check the forces") : out;
  }

  std::string fix_for_dt(double suggested) const {
    if (settings_.adaptive) return "fix: " + advice();
    // A broken state can give limits of 0 or NaN: no number to suggest then.
    const std::string dt = suggested > 0 && std::isfinite(suggested) ? fmt::format("a smaller dt (at most {:.3g})", suggested)
                                                                     : std::string("a much smaller dt");
    return fmt::format("fix: {}, or dt = \"adaptive\"; {}", dt, advice());
  }

  // A smaller step to suggest: a quarter of this one, or the tightest limit.
  double suggested_dt() const {
    const double base = settings_.adaptive ? last_dt_ : settings_.dt;
    return std::min(base / 4, tightest().dt);
  }

  [[noreturn]] void throw_non_finite(std::size_t index) const {
    const std::string state =
        ranks_ ? from_owner(index, [&](std::size_t i) { return particle_state(i); }) : particle_state(index);
    if (!started_)  // start(): the forces of the initial state, no step taken
      throw SimulationError(
          fmt::format("before the first step: blow-up: the forces of the initial state are not finite: {}; no time "
                      "step is involved: two particles at the same place without softening, or an initial value out "
                      "of range; fix: {}",
                      state, advice()),
          BlowUpCause::NonFinite);
    throw SimulationError(fmt::format("{}: blow-up: {}; the time step {} is probably too large for the forces; {}", where(),
                                      state, last_dt_, fix_for_dt(suggested_dt())),
                          BlowUpCause::NonFinite);
  }

  // "particle id 7 has a non-finite velocity (x = ..., v = ...)": every
  // non-finite quantity of local particle i, in field order.
  std::string particle_state(std::size_t i) const {
    std::string names;
    for (const auto& f : particles_.fields())
      for (int c = 0; c < f.components; ++c)
        if (!std::isfinite(f.data[static_cast<std::size_t>(c)][i])) {
          names += fmt::format("{}{}", names.empty() ? "" : ", ", f.name);
          break;
        }
    return fmt::format("particle id {} has a non-finite {} (x = ({}, {}, {}), v = ({}, {}, {}))", particles_.id[i], names,
                       particles_.position.x[i], particles_.position.y[i], particles_.position.z[i],
                       particles_.velocity.x[i], particles_.velocity.y[i], particles_.velocity.z[i]);
  }

  std::string escape_message(const integrate::Escape& e) const {
    return fmt::format(
        "{}: blow-up: particle id {} left the box: it ended a position update {:.3g} outside a wall, more than "
        "the kernel support h = {:.3g} (that update moved it {:.3g} in dt = {:.3g}: speed {:.3g}, acceleration {:.3g}); {}",
        where(), e.id, e.excess, settings_.escape_length, e.displacement, last_dt_, e.speed, e.acceleration,
        fix_for_dt(suggested_dt()));
  }

  std::string condition_message(const StepLimit& l, double dt, std::string_view alternative) const {
    const LimitText text = solvers_.at(l.source)->explain(l, particle_id(l.particle));
    return fmt::format("{}: blow-up: time step too large: dt = {:.6g} exceeds {}; fix: dt <= {:.6g}, {}{}{}", where(), dt,
                       text.rule, l.dt, alternative, text.fix.empty() ? "" : ", ", text.fix);
  }

  [[noreturn]] void throw_collapse(double proposal) const {
    const StepLimit& l = tightest();
    throw SimulationError(
        fmt::format("{}: blow-up: the adaptive time step collapsed to {:.3g}, below dt_min = {:.3g}: the {} condition "
                    "is set by particle id {} ({} = {:.3g}); fix: {}",
                    where(), proposal, clock_.dt_floor, l.condition, particle_id(l.particle), l.quantity, l.value,
                    advice()),
        BlowUpCause::StepCollapse);
  }

  void report(BlowUpCause cause, std::string message) {
    if (settings_.on_blow_up == OnBlowUp::Warn) {
      events_.push_back({cause, std::move(message)});
      return;
    }
    throw SimulationError(message, cause);
  }

  ParticleSet<Real> particles_;
  SimulationSettings settings_;
  std::unique_ptr<integrate::Stepper<Real>> stepper_;
  std::vector<std::unique_ptr<Solver<Real>>> solvers_;
  spatial::ParticleOrder<Real> order_;
  std::shared_ptr<const boundary::MovingBoundaries> moving_;  // null: every boundary particle static
  std::unique_ptr<dist::RankOrder<Real>> ranks_;  // several ranks: the global order (order_ unused)
  std::uint64_t evaluations_on_ranks_ = 0;
  bool last_evaluation_partial_ = false;    // the last compute_forces() was of the active particles only
  std::vector<std::uint64_t> rank_work_;    // add_rank_costs()'s solver counts, before the bins' weights
  bool whole_on_root_ = false;  // distribute(): the set on rank 0 alone until start() or resume()
  mutable ParticleSet<Real> gathered_;  // whole_particles() on ranks (filled on rank 0)
  mutable std::pair<std::uint64_t, std::uint64_t> gathered_stamp_{};  // the step and epoch it was gathered at
  mutable bool gathered_valid_ = false;
  PhaseTimers timers_;
  ScanNeeds needs_;
  SimulationClock clock_;
  double last_dt_ = 0;
  StepScan scan_;
  std::vector<StepLimit> limits_;
  std::vector<GuardEvent> events_;
  bool prepared_ = false;
  bool started_ = false;
};

// Compiled once, in src/sim/simulation.cpp: users link the float and double copies
// instead of compiling them again.
extern template class Simulation<float>;
extern template class Simulation<double>;

}  // namespace swirl
