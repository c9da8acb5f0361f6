// Where the ranks' key ranges end: cut keys balanced by a deterministic cost
// (docs/design/mpi.md, "Decomposition").
//
// Each particle carries a cost, an integer from the last step's work (its
// neighbour count, its share of its group's interactions), never a timing:
// the cuts, and so the run's bits, must not depend on the machine's noise.
// A cut may only fall on a boundary of the key space's octree at `depth`
// (a multiple of 2^(3·(21−depth)) in 63-bit Morton keys): a cell of that depth
// is never split between ranks. The cuts split the total cost as evenly as those
// boundaries allow: cut r is the first boundary below which at least
// r/size of the total cost lies. They are found by bisection over the
// boundaries, one exact integer all-reduce per step (3·depth + 1 steps), so
// every rank computes the same cuts from its own particles alone.
//
// Imbalance: the largest rank's cost over the mean. A run rebalances (new cuts)
// when it passes the scene's threshold; between rebalances particles that
// cross a cut migrate (distribute_in_key_order with the same cuts).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "swirl/dist/communicator.hpp"

namespace swirl::dist {

inline constexpr int kKeyDepth = 21;  // levels of the 63-bit Morton key (21 bits per axis)

// keys: this rank's particles' keys (any order); costs: one per key.
std::vector<std::uint64_t> balanced_cut_keys(const Communicator& comm, std::span<const std::uint64_t> keys,
                                             std::span<const std::uint64_t> costs, int depth = kKeyDepth);

// The total cost each rank's range would hold with these cuts (every rank
// gets the same list). keys need not be sorted.
std::vector<std::uint64_t> cost_per_rank(const Communicator& comm, std::span<const std::uint64_t> keys,
                                         std::span<const std::uint64_t> costs,
                                         std::span<const std::uint64_t> cut_keys);

// max / mean of cost_per_rank (1 when the total is 0).
double imbalance(std::span<const std::uint64_t> rank_costs);

}  // namespace swirl::dist
