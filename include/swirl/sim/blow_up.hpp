// The blow-up guard's vocabulary: what can go wrong in a step, what the run
// then does, and the error that stops it.
//
// After every step Simulation checks (docs/stability.md):
//   NonFinite     a particle has a NaN or infinite field (always stops: nothing
//                 computed from it afterwards means anything);
//   LeftDomain    a particle ended a position update further outside the box
//                 than the SPH kernel support h (a step that keeps the CFL
//                 condition moves a particle less than h);
//   TimeStep      a fixed Δt exceeds a time-step condition (a solver's add_limits())
//                 of the state the next step starts from;
//   StepCollapse  an adaptive Δt fell below its floor (dt_min);
//   NotConverged  an iterative pressure solver (DFSPH, sph/dfsph_stepper.hpp)
//                 reached its iteration cap above its tolerance;
//   EnergyDrift   the relative energy error of a run whose every force conserves
//                 energy passed simulation.max_energy_error (checked at each
//                 diagnostics row, i.e. each output time; sim/run.hpp).
// Every message names the step, the time, a particle id, the offending
// quantity and a suggested fix.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace swirl {

enum class BlowUpCause { NonFinite, LeftDomain, TimeStep, StepCollapse, EnergyDrift, NotConverged };
inline constexpr std::size_t kBlowUpCauses = 6;

// "non-finite state", "left the domain", "time-step condition", "time step collapsed", "energy error",
// "solver did not converge".
inline std::string_view to_string(BlowUpCause cause) {
  switch (cause) {
    case BlowUpCause::NonFinite: return "non-finite state";
    case BlowUpCause::LeftDomain: return "left the domain";
    case BlowUpCause::TimeStep: return "time-step condition";
    case BlowUpCause::StepCollapse: return "time step collapsed";
    case BlowUpCause::EnergyDrift: return "energy error";
    case BlowUpCause::NotConverged: return "solver did not converge";
  }
  return "?";
}

// What a failed check does: stop the run (the default), or warn and go on
// (experts; a non-finite state stops anyway). Off skips the checks other than
// the non-finite position and velocity (the state before this guard existed):
// it exists to measure what the checks cost.
enum class OnBlowUp { Stop, Warn, Off };

// A run that cannot go on. what() names the step, time, particle id, the
// offending quantity and a suggested fix.
class SimulationError : public std::runtime_error {
 public:
  explicit SimulationError(const std::string& message, BlowUpCause cause = BlowUpCause::NonFinite)
      : std::runtime_error(message), cause_(cause) {}
  BlowUpCause cause() const { return cause_; }

 private:
  BlowUpCause cause_;
};

// A failed check that did not stop the run (OnBlowUp::Warn).
struct GuardEvent {
  BlowUpCause cause = BlowUpCause::TimeStep;
  std::string message;
};

}  // namespace swirl
