// ActiveSet: the particles one force evaluation must compute.
//
// Individual (block) time steps (integrate/block_steps.hpp) give each particle
// a power-of-two time bin, stored in the integer field "time_bin"; at a given
// sub-step the particles whose steps end are exactly those with
// bin >= min_bin (a finer bin's steps nest inside every coarser one's). An
// evaluation with an active set must leave correct acceleration (and potential)
// for those particles; what it leaves for the others is unspecified (the
// block stepper never reads it before their own evaluation). A set without
// bins is every particle: the ordinary evaluation.
#pragma once

#include <cstddef>
#include <cstdint>

namespace swirl {

struct ActiveSet {
  const std::int32_t* bins = nullptr;  // per particle, in the particles' current order; null: all active
  std::int32_t min_bin = 0;

  bool all() const { return bins == nullptr || min_bin <= 0; }
  bool contains(std::size_t i) const { return all() || bins[i] >= min_bin; }
};

}  // namespace swirl
