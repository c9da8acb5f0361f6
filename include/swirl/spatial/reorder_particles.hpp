// reorder_particles(): ParticleSet::reorder in parallel, for a sort every step.
//
// Moves every field (built-in and extra, and the ids) so that the particle at
// old index order[i] ends at index i (a gather). Fields are gathered four at a
// time into four scratch arrays block by block (for_blocks: disjoint writes,
// deterministic) and swapped in, so the extra memory is four fields (and the
// ids), not a second particle set, and a reorder costs ⌈fields/4⌉ fork/joins.
// Precondition (not checked, hot path): order is a permutation of 0..size()-1;
// the sorts that make it (parallel::RadixSort) guarantee it.
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
  void apply(ParticleSet<Real>& p, std::span<const std::uint32_t> order, std::size_t block_size) {
    const std::size_t n = p.size();
    if (order.size() != n) throw std::invalid_argument("reorder_particles: order has the wrong length");
    std::vector<AlignedVector<Real>*> fields;
    p.for_each_array([&](AlignedVector<Real>& a) { fields.push_back(&a); });
    for (auto& s : scratch_) s.resize(n);
    ids_.resize(n);
    // kGroup fields per parallel loop (the ids with the first group): one
    // fork/join per group instead of one per field — the fork/joins, not the
    // bytes, made this stage scale worst on 2 threads at 35 000 particles.
    for (std::size_t first = 0; first < fields.size(); first += kGroup) {
      const std::size_t count = std::min(kGroup, fields.size() - first);
      parallel::for_blocks_pinned("reorder", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t k = 0; k < count; ++k) {
          const Real* from = fields[first + k]->data();
          Real* to = scratch_[k].data();
          for (std::size_t i = b; i < e; ++i) to[i] = from[order[i]];
        }
        if (first == 0)
          for (std::size_t i = b; i < e; ++i) ids_[i] = p.id[order[i]];
      });
      for (std::size_t k = 0; k < count; ++k) fields[first + k]->swap(scratch_[k]);
    }
    p.id.swap(ids_);
  }

  // Bytes of scratch kept between calls.
  std::size_t bytes() const {
    std::size_t b = ids_.capacity() * sizeof(std::uint64_t);
    for (const auto& s : scratch_) b += s.capacity() * sizeof(Real);
    return b;
  }

 private:
  static constexpr std::size_t kGroup = 4;
  std::array<AlignedVector<Real>, kGroup> scratch_;
  AlignedVector<std::uint64_t> ids_;
};

}  // namespace swirl::spatial
