// Stepper<Real>: the seam through which a time-integration method enters a
// simulation. A stepper owns the whole of one step: which per-particle updates
// run, where the force evaluation sits between them, where the boundaries act,
// and the scan of the new state fused into its last pass.
//
// The simulation gives it a Forces object (zero a, sort the particles when a
// solver asks for it, every solver adds its acceleration) and a StepRequest;
// it returns what the guard needs. A method that needs several force
// evaluations per step (a predictor–corrector, a pressure solver's
// iterations), or steps of its own per particle (individual time steps),
// implements this interface and calls forces.evaluate() as often as it needs.
//
// Contract: between steps x, v and a (and every solver field) belong to the
// same time; passes run through parallel::for_blocks* over fixed blocks and
// write only their own block, so a step is bit-identical for any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/core/named_values.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/force/step_scan.hpp"

namespace swirl::dist {
class Communicator;
}

namespace swirl::integrate {

// The integer field of individual time steps: each particle's bin
// (core/active_set.hpp). Declared by a stepper that uses evaluate_active().
inline constexpr std::string_view kTimeBinField = "time_bin";

// The force evaluation a stepper calls: a ← F(x) at the given time.
class Forces {
 public:
  virtual ~Forces() = default;
  virtual void evaluate(double time) = 0;
  // The same for the particles whose kTimeBinField is >= min_bin; the others'
  // acceleration is left unspecified (solvers may compute it or not).
  virtual void evaluate_active(double time, std::int32_t min_bin) {
    (void)min_bin;
    evaluate(time);
  }
};

// One step to take.
struct StepRequest {
  double dt = 0;               // the step, in the positions' time unit
  double t_next = 0;           // the time the step ends at
  std::size_t block_size = 1;  // work-block size
  bool scan = true;            // scan the new state (StepScan) in the last pass; false: only non-finite x, v
  ScanNeeds needs;             // what the scan measures beyond |v|max, |a|max
  double escape_length = 0;    // > 0 with a box: report the particle furthest outside beyond this
  PhaseTimers* timers = nullptr;
  // Several ranks (each stepping its own particles): what a stepper decides
  // for all particles at once (the block stepper's finest bin) is reduced
  // over them. Null: one rank.
  const dist::Communicator* ranks = nullptr;
};

// A particle that ended a position update further outside the box than
// escape_length. By id: the force evaluation that follows may reorder.
struct Escape {
  bool found = false;
  std::uint64_t id = 0;
  double excess = 0;  // distance outside the box
  double speed = 0;         // |v| at the start of the position update
  double acceleration = 0;  // |a| at the start of the position update
  double displacement = 0;  // how far the update moved it (before the wall's projection)
};

struct StepOutcome {
  StepScan scan;  // of the new state
  Escape escape;
  // A stepper that divides the step (individual time steps): the finest sub-step
  // the next step will use for its particles, checked by the guard against
  // the solvers' limits in place of the whole step; 0: the step is not divided.
  double finest_dt = 0;
  std::string finest_fix;  // what relaxes it, for the guard's message (e.g. "a larger max_bin")
  // An iterative solver that stopped at its cap above its tolerance: what and
  // by how much, and the fix (the guard reports it as "solver did not converge").
  std::string not_converged;
};

template <class Real>
class Stepper {
 public:
  virtual ~Stepper() = default;
  // "velocity_verlet", "leapfrog", ...
  virtual std::string_view name() const = 0;
  // Fields the method keeps beyond the built-ins.
  virtual void declare_fields(ParticleSet<Real>& /*particles*/) {}
  // Makes the state between steps from x₀, v₀ (a₀ = F(x₀) and whatever the method keeps).
  virtual void start(ParticleSet<Real>& particles, Forces& forces, double time, std::size_t block_size) = 0;
  // Advances by request.dt.
  virtual StepOutcome advance(ParticleSet<Real>& particles, Forces& forces, const StepRequest& request) = 0;
  // Summary figures over the run so far (e.g. sub-steps taken).
  virtual void add_metrics(NamedValues& /*out*/) const {}
  // Its columns of the per-frame diagnostics log and their values (e.g. a
  // pressure solver's iterations), after the solvers' columns.
  virtual std::vector<std::string> diagnostic_columns() const { return {}; }
  virtual void add_diagnostics(std::vector<double>& /*row*/) const {}
  // State across a checkpoint beyond the particle fields (names prefixed with name() + ".").
  virtual void save_state(NamedValues& /*out*/) const {}
  virtual void load_state(const NamedValues& /*values*/) {}
};

// Compiled once, in src/integrate/stepper.cpp: users link the float and double copies
// instead of compiling them again.
extern template class Stepper<float>;
extern template class Stepper<double>;

}  // namespace swirl::integrate
