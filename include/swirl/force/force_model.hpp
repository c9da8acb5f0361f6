// ForceModel<Real>: the seam through which physics enters a simulation.
//
// Each step the stepper zeroes every particle's acceleration and then asks each
// force model, in the order they were added, to add its acceleration at the
// current positions. The SPH solver (density, pressure, pressure and viscosity
// forces), the gravity solvers and external fields are all force models.
//
// Contract for add_acceleration():
//  - reads positions (and velocities, masses, its own fields), adds into
//    particles.acceleration; may also write fields it owns (density, pressure);
//  - runs its loops through parallel::for_blocks with ctx.block_size and gives
//    bit-identical results for any thread count;
//  - throws on failure with a message a user can act on.
#pragma once

#include <cstddef>
#include <string_view>

#include "swirl/core/particle_set.hpp"
#include "swirl/core/phase_timers.hpp"

namespace swirl {

// What a force model may know about the step it is called in.
struct ForceContext {
  double time = 0;             // simulated time of the positions, s
  std::size_t block_size = 1;  // work-block size for parallel passes
  PhaseTimers* timers = nullptr;  // where a model may time its own sub-phases
};

template <class Real>
class ForceModel {
 public:
  virtual ~ForceModel() = default;
  // A short name for summaries and messages, e.g. "gravity".
  virtual std::string_view name() const = 0;
  // Adds this model's acceleration into particles.acceleration (see contract above).
  virtual void add_acceleration(ParticleSet<Real>& particles, const ForceContext& ctx) = 0;
};

}  // namespace swirl
