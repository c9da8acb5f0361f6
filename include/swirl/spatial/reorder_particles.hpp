// reorder_particles(): ParticleSet::reorder in parallel, for a sort every step.
//
// Moves every field (built-in and extra, real and integer, and the ids) so that
// the particle at old index order[i] ends at index i (a gather). Fields are
// gathered in groups: each parallel loop moves up to four real fields and up
// to four integer fields block by block into scratch arrays (for_blocks:
// disjoint writes, deterministic; a gather copies bits, so the result is the
// same for any thread count) and swaps them in. The extra memory is four real
// fields, at most four integer fields and the ids, not a second particle set,
// and a reorder costs ⌈max(real, integer fields)/4⌉ fork/joins: integer fields
// ride along with the real ones' loops. The slow twin is ParticleSet::reorder.
// Precondition (not checked, hot path): order is a permutation of 0..size()-1;
// the sorts that make it (parallel::RadixSort) guarantee it. select() gathers
// a subset (the distributed sort's: the particles that stayed and arrived).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::spatial {

template <class Real>
class ParticleReorder {
 public:
  using Int = typename ParticleSet<Real>::int_type;

  void apply(ParticleSet<Real>& p, std::span<const std::uint32_t> order, std::size_t block_size) {
    if (order.size() != p.size()) throw std::invalid_argument("reorder_particles: order has the wrong length");
    select(p, order, block_size);
  }

  // The same gather to a set of picked.size() particles: the particle at old
  // index picked[i] ends at index i, the ones not picked are dropped (each
  // index < size(), none twice: not checked). apply() is select() with a
  // permutation.
  void select(ParticleSet<Real>& p, std::span<const std::uint32_t> order, std::size_t block_size) {
    const std::size_t n = order.size();
    std::vector<AlignedVector<Real>*> reals;
    p.for_each_array([&](AlignedVector<Real>& a) { reals.push_back(&a); });
    std::vector<AlignedVector<Int>*> ints;
    p.for_each_int_array([&](AlignedVector<Int>& a) { ints.push_back(&a); });
    ids_.resize(n);
    // kGroup fields of each kind per parallel loop (the ids with the first
    // group): one fork/join per group instead of one per field — the
    // fork/joins, not the bytes, made this stage scale worst on 2 threads at
    // 35 000 particles. There is always a first group: the built-in fields.
    const std::size_t groups = std::max(groups_of(reals.size()), groups_of(ints.size()));
    for (std::size_t g = 0; g < groups; ++g) {
      const std::size_t first = g * kGroup;
      const std::size_t real_count = count_in_group(reals.size(), first);
      const std::size_t int_count = count_in_group(ints.size(), first);
      // Sized per group: the scratch holds the arrays the group before swapped out (of the old size, when
      // select() shrinks). Integer scratch only as far as used: a run without integer fields keeps none.
      for (std::size_t k = 0; k < real_count; ++k) scratch_[k].resize(n);
      for (std::size_t k = 0; k < int_count; ++k) int_scratch_[k].resize(n);
      parallel::for_blocks_pinned("reorder", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t k = 0; k < real_count; ++k) gather(reals[first + k]->data(), scratch_[k].data(), order, b, e);
        for (std::size_t k = 0; k < int_count; ++k) gather(ints[first + k]->data(), int_scratch_[k].data(), order, b, e);
        if (g == 0) gather(p.id.data(), ids_.data(), order, b, e);
      });
      for (std::size_t k = 0; k < real_count; ++k) reals[first + k]->swap(scratch_[k]);
      for (std::size_t k = 0; k < int_count; ++k) ints[first + k]->swap(int_scratch_[k]);
    }
    p.id.swap(ids_);
  }

  // Bytes of scratch kept between calls.
  std::size_t bytes() const {
    std::size_t b = ids_.capacity() * sizeof(std::uint64_t);
    for (const auto& s : scratch_) b += s.capacity() * sizeof(Real);
    for (const auto& s : int_scratch_) b += s.capacity() * sizeof(Int);
    return b;
  }

 private:
  static constexpr std::size_t kGroup = 4;

  static std::size_t groups_of(std::size_t fields) { return (fields + kGroup - 1) / kGroup; }
  static std::size_t count_in_group(std::size_t fields, std::size_t first) {
    return first < fields ? std::min(kGroup, fields - first) : 0;
  }
  template <class T>
  static void gather(const T* from, T* to, std::span<const std::uint32_t> order, std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) to[i] = from[order[i]];
  }

  std::array<AlignedVector<Real>, kGroup> scratch_;
  std::array<AlignedVector<Int>, kGroup> int_scratch_;
  AlignedVector<std::uint64_t> ids_;
};

// Compiled once, in src/spatial/reorder_particles.cpp: users link the float and double copies
// instead of compiling them again.
extern template class ParticleReorder<float>;
extern template class ParticleReorder<double>;

}  // namespace swirl::spatial
