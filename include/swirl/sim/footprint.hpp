#pragma once
// What a scene needs of a machine, estimated from the scene alone, before
// anything is allocated: the memory of each rank of a run and the size of
// one frame, in bytes. An estimate (docs/design/mpi.md, "Memory"): it counts
// every size the scene sets (the particle count, the neighbours its smoothing
// length gives, the hash table's buckets, a dense cell table's cells, the
// tree's nodes) and, on several ranks, each rank's share of the particles,
// its ghosts and imported tree, and rank 0's whole copy (it builds the
// particles and gathers every frame). It errs high, never by orders of
// magnitude.

#include <cstdint>
#include <string>
#include <vector>

#include "swirl/scene/scene.hpp"

namespace swirl::sim {

struct Footprint {
  // Bytes on each rank, index = rank (one entry for a run without ranks).
  // Every rank but 0 needs the same; rank 0 needs the most.
  std::vector<double> memory;
  double frame = 0;  // bytes of one .vtp frame
};

// The footprint of `scene` run on `ranks` ≥ 1 ranks.
Footprint footprint(const scene::Scene& scene, int ranks = 1);

// Where a rank runs and what that host has free: the input of
// memory_refusal(), one per rank, index = rank.
struct RankHost {
  std::string host;          // ranks with the same name share its memory
  std::uint64_t free_bytes;  // what that rank saw free (0: unknown, not checked)
};

// Why `scene` does not fit, or "" when it does: on one rank, its memory
// against 90 % of the free memory; on several, the sum of the needs of the
// ranks that share a host against 90 % of the least free memory they saw.
// The message names the scene's file, the particle count, the estimate per
// rank (and rank 0's) and the host that is short.
std::string memory_refusal(const scene::Scene& scene, const std::vector<RankHost>& hosts);

// The free physical memory of this machine now, in bytes (0: unknown).
std::uint64_t memory_available();

}  // namespace swirl::sim
