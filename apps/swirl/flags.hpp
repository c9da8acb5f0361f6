// Checks of the CLI's numeric flags, applied to the text before CLI11 converts
// it. CLI11's own conversion clamps an overflowing count to its type's maximum
// (--steps 99999999999999999999999 became 2^64 - 1), accepts nan and inf as
// numbers, and its range checks print the type's limits (a 309-digit number).
// These refuse instead, with a message CLI11 prefixes with the flag's name; the
// process then exits with status 2 like every usage error.
#pragma once

#include <cstdint>

#include <CLI/CLI.hpp>

#include "swirl/sim/run.hpp"

namespace swirl::cli {

// The most steps a run can count (sim/run.hpp: n·dt is exact in a double only
// up to 2^53 steps, and a count beyond that could never be reached anyway).
using sim::kMaxSteps;

// The most of anything else the CLI counts (particles, iterations, buckets):
// what an int holds, far beyond what a run on one machine can use.
inline constexpr std::uint64_t kMaxCount = 2147483647;

// A whole number in [lo, hi], written as decimal digits (no sign, no exponent).
CLI::Validator whole_number(std::uint64_t lo, std::uint64_t hi);
// A finite number greater than 0 (refuses nan, inf, 0 and negatives).
CLI::Validator positive_finite();
// A number in [lo, hi] (CLI::Range lets nan through).
CLI::Validator number_in(double lo, double hi);
// A finite number of at least 0.
CLI::Validator non_negative_finite();
// A thread count: 1 to parallel::max_thread_count().
CLI::Validator thread_count();

}  // namespace swirl::cli
