// The global particle order across ranks (docs/design/mpi.md, "The invariant").
//
// Invariant: the ranks' particles, concatenated in rank order, are the one-rank
// memory order. Rank r holds the contiguous range [first_r, first_r + n_r) of
// the global order, so a particle's global index is first_r + its local index
// and need not be stored.
//
// distribute_in_key_order() restores the invariant after the keys changed (a
// new step's positions) and, at the same time, moves every particle to the rank
// whose key range holds its key (migration; a rebalance is the same call with
// new cuts). Afterwards each rank's particles are sorted by (key, previous
// global index): since the previous global index is the previous memory order
// of a one-rank run, the concatenation is exactly the stable sort by key of
// parallel::RadixSort on one rank, whatever the rank count. Every field moves
// (real, integer, ids: all of ParticleSet), bit for bit.
//
// Cut keys: ranks own half-open key ranges [cut[r-1], cut[r]) with cut[-1] = 0
// and cut[size-1] = +inf; cut_keys holds the size-1 inner cuts, nondecreasing.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/parallel/radix_sort.hpp"
#include "swirl/spatial/reorder_particles.hpp"

namespace swirl::dist {

// Particles per block of the reorder's parallel gather (scheduling only: any
// value gives the same bits).
inline constexpr std::size_t kReorderBlock = 4096;

// The rank whose key range holds key.
inline int owner_of(std::uint64_t key, std::span<const std::uint64_t> cut_keys) {
  return static_cast<int>(std::upper_bound(cut_keys.begin(), cut_keys.end(), key) - cut_keys.begin());
}

// Up to this many cuts, owners_of() and sum_per_rank() compare each key with
// every cut (branch-free, nothing carried from one particle to the next but
// a sum in a register); beyond it, a binary search per key. Either gives the
// same integers: the choice is speed only (once per sort, over every particle).
inline constexpr std::size_t kFewCuts = 8;

// destination[i] = owner_of(keys[i], cut_keys) for every i.
inline void owners_of(std::span<const std::uint64_t> keys, std::span<const std::uint64_t> cut_keys,
                      std::span<int> destination) {
  if (cut_keys.size() > kFewCuts) {
    for (std::size_t i = 0; i < keys.size(); ++i) destination[i] = owner_of(keys[i], cut_keys);
    return;
  }
  const std::uint64_t* cut = cut_keys.data();
  const std::size_t cuts = cut_keys.size();
  for (std::size_t i = 0; i < keys.size(); ++i) {
    int d = 0;
    for (std::size_t c = 0; c < cuts; ++c) d += keys[i] >= cut[c] ? 1 : 0;
    destination[i] = d;
  }
}

// per_rank[r] += Σ weight(i) over the keys in rank r's range (per_rank: one
// entry per rank, cut_keys.size() + 1). With few cuts: for each cut the sum
// over the keys at or above it, one pass each, and the differences.
template <class Weight>
void sum_per_rank(std::span<const std::uint64_t> keys, std::span<const std::uint64_t> cut_keys, Weight&& weight,
                  std::span<std::uint64_t> per_rank) {
  const std::size_t n = keys.size(), cuts = cut_keys.size();
  if (cuts > kFewCuts) {
    for (std::size_t i = 0; i < n; ++i) per_rank[static_cast<std::size_t>(owner_of(keys[i], cut_keys))] += weight(i);
    return;
  }
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < n; ++i) total += weight(i);
  std::uint64_t from_previous = total;  // Σ weight of the keys at or above the previous cut (all, before the first)
  for (std::size_t c = 0; c < cuts; ++c) {
    const std::uint64_t cut = cut_keys[c];
    std::uint64_t from_this = 0;
    for (std::size_t i = 0; i < n; ++i) from_this += keys[i] >= cut ? weight(i) : 0;
    per_rank[c] += from_previous - from_this;  // the keys in [previous cut, this cut)
    from_previous = from_this;
  }
  per_rank[cuts] += from_previous;
}

// What one call moved: particles sent to other ranks (this rank's count).
struct Distribution {
  std::uint64_t first_global_index = 0;  // of this rank's first particle, in the new order
  std::uint64_t global_count = 0;
  std::size_t sent_away = 0;
};

// What distribute_in_key_order() keeps between calls (its sort's and its
// reorder's buffers, so that a step does not allocate and fault them in anew).
template <class Real>
struct DistributeWorkspace {
  parallel::RadixSort<std::uint64_t> sorter;
  spatial::ParticleReorder<Real> reorder;
  std::vector<int> destination;              // per own particle: its rank
  std::vector<std::uint32_t> source, picked;  // the new order's particles, before and after the sort
  std::vector<std::uint64_t> unsorted;        // their keys before the sort
};

// particles[i] has key keys[i] and global index first_global_index + i (the
// previous order). On return particles and keys hold this rank's range of the
// new global order. Collective: every rank calls it with the same cut_keys.
// key_bits: the keys' significant bits (every key < 2^key_bits, checked; the
// sort looks at no more, as ParticleOrder's at its frame's key_bits).
//
// Only the particles that leave are packed into records and sent; those that
// stay do not move until the one gather that sorts. The new order before the
// sort is the arrivals from lower ranks, the staying particles, the arrivals
// from higher ranks: the previous global order (each source held a contiguous
// range of it and sent in that order), so the stable sort by key (the one-rank
// radix sort, parallel and linear) is the sort by (key, previous global index).
template <class Real>
Distribution distribute_in_key_order(const Communicator& comm, ParticleSet<Real>& particles,
                                     std::vector<std::uint64_t>& keys, std::uint64_t first_global_index,
                                     std::span<const std::uint64_t> cut_keys, unsigned key_bits,
                                     DistributeWorkspace<Real>& work) {
  using Int = typename ParticleSet<Real>::int_type;
  const std::size_t n = particles.size();
  if (keys.size() != n) throw std::invalid_argument("distribute_in_key_order: one key per particle is needed");
  if (cut_keys.size() + 1 != static_cast<std::size_t>(comm.size()))
    throw std::invalid_argument("distribute_in_key_order: size()-1 cut keys are needed");
  if (!std::is_sorted(cut_keys.begin(), cut_keys.end()))
    throw std::invalid_argument("distribute_in_key_order: cut keys must be nondecreasing");
  if (key_bits == 0 || key_bits > 64) throw std::invalid_argument("distribute_in_key_order: key_bits must be 1 to 64");

  std::size_t real_arrays = 0, int_arrays = 0;
  particles.for_each_array([&](const AlignedVector<Real>&) { ++real_arrays; });
  particles.for_each_int_array([&](const AlignedVector<Int>&) { ++int_arrays; });
  // One record per particle: key, previous global index, id, the real fields, the integer fields.
  const std::size_t record = 3 * sizeof(std::uint64_t) + real_arrays * sizeof(Real) + int_arrays * sizeof(Int);

  const auto ranks = static_cast<std::size_t>(comm.size());
  const auto me = comm.rank();
  std::vector<int>& destination = work.destination;
  destination.resize(n);
  std::vector<std::size_t> per_rank(ranks, 0);
  const std::uint64_t above_bits = key_bits == 64 ? 0 : ~((std::uint64_t{1} << key_bits) - 1);
  std::uint64_t stray_bits = 0;
  owners_of(keys, cut_keys, destination);
  sum_per_rank(keys, cut_keys, [](std::size_t) { return std::uint64_t{1}; }, per_rank);
  for (std::size_t i = 0; i < n; ++i) stray_bits |= keys[i] & above_bits;
  if (stray_bits != 0) throw std::invalid_argument("distribute_in_key_order: a key has bits above key_bits");
  const std::size_t staying = per_rank[static_cast<std::size_t>(me)];
  std::vector<Bytes> send(ranks);
  for (std::size_t d = 0; d < ranks; ++d)
    if (d != static_cast<std::size_t>(me)) send[d].resize(per_rank[d] * record);
  auto put = [](std::byte*& at, const auto& value) {
    std::memcpy(at, &value, sizeof(value));
    at += sizeof(value);
  };
  std::vector<std::size_t> filled(ranks, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const int d = destination[i];
    if (d == me) continue;
    std::byte* at = send[static_cast<std::size_t>(d)].data() + filled[static_cast<std::size_t>(d)]++ * record;
    put(at, keys[i]);
    put(at, std::uint64_t{first_global_index + i});
    put(at, particles.id[i]);
    particles.for_each_array([&](const AlignedVector<Real>& a) { put(at, a[i]); });
    particles.for_each_int_array([&](const AlignedVector<Int>& a) { put(at, a[i]); });
  }
  Distribution result;
  result.sent_away = n - staying;

  const std::vector<Bytes> received = comm.all_to_all(send);
  send.clear();
  std::size_t lower = 0, arrivals = 0;
  for (std::size_t r = 0; r < ranks; ++r) {
    if (received[r].size() % record != 0) throw std::runtime_error("distribute_in_key_order: a rank sent a partial record");
    arrivals += received[r].size() / record;
    if (r < static_cast<std::size_t>(me)) lower += received[r].size() / record;
  }
  const std::size_t count = staying + arrivals;
  if (n + arrivals > 0xffffffffu) throw std::invalid_argument("distribute_in_key_order: more than 2^32 - 1 particles on a rank");
  // The arrivals are unpacked behind the particles already here (indices n …),
  // and nothing else moves until the one gather at the end.
  particles.resize(n + arrivals);
  keys.resize(n + arrivals);
  auto get = [](const std::byte*& at, auto& value) {
    std::memcpy(&value, at, sizeof(value));
    at += sizeof(value);
  };
  // The new order before the sort, as indices into that layout: the lower
  // ranks' arrivals, the staying particles, the higher ranks' arrivals. The
  // arrivals' previous global indices are checked to be in that order (below
  // this rank's range from lower ranks, above it from higher ones; an empty
  // rank's range has no place to check against).
  std::vector<std::uint32_t>& source = work.source;
  std::vector<std::uint64_t>& unsorted = work.unsorted;
  source.resize(count);
  unsorted.resize(count);
  std::size_t next = n;  // where the next arrival is unpacked
  std::size_t j = 0;     // its place in the new order before the sort
  bool any = false;
  std::uint64_t previous = 0;
  for (std::size_t r = 0; r < ranks; ++r) {
    if (r == static_cast<std::size_t>(me)) {
      for (std::size_t i = 0; i < n; ++i)
        if (destination[i] == me) source[j] = static_cast<std::uint32_t>(i), unsorted[j++] = keys[i];
      if (n > 0) any = true, previous = first_global_index + n - 1;
      continue;
    }
    const Bytes& b = received[r];
    for (const std::byte* at = b.data(); at != b.data() + b.size(); ++next, ++j) {
      std::uint64_t index = 0;
      get(at, keys[next]);
      get(at, index);
      if ((any && index <= previous) || (r < static_cast<std::size_t>(me) && n > 0 && index >= first_global_index))
        throw std::logic_error("distribute_in_key_order: the ranks' particles were not in the global order");
      any = true, previous = index;
      get(at, particles.id[next]);
      particles.for_each_array([&](AlignedVector<Real>& a) { get(at, a[next]); });
      particles.for_each_int_array([&](AlignedVector<Int>& a) { get(at, a[next]); });
      source[j] = static_cast<std::uint32_t>(next), unsorted[j] = keys[next];
    }
  }
  work.sorter.sort(unsorted, key_bits);
  std::vector<std::uint32_t>& picked = work.picked;
  picked.resize(count);
  const auto order = work.sorter.order();
  bool moved = count != n;  // as ParticleOrder: no gather when every particle keeps its place
  for (std::size_t k = 0; k < count; ++k) {
    picked[k] = source[order[k]];
    moved = moved || picked[k] != k;
  }
  if (moved) {
    work.reorder.select(particles, picked, kReorderBlock);
    keys.assign(work.sorter.keys().begin(), work.sorter.keys().end());
  }

  result.first_global_index = comm.exclusive_prefix_sum(count);
  result.global_count = comm.sum(static_cast<std::uint64_t>(count));
  return result;
}

// The same with buffers of its own (a caller that sorts once).
template <class Real>
Distribution distribute_in_key_order(const Communicator& comm, ParticleSet<Real>& particles,
                                     std::vector<std::uint64_t>& keys, std::uint64_t first_global_index,
                                     std::span<const std::uint64_t> cut_keys) {
  DistributeWorkspace<Real> work;
  return distribute_in_key_order(comm, particles, keys, first_global_index, cut_keys, 64, work);
}

}  // namespace swirl::dist
