// reorder_particles(): ParticleSet::reorder in parallel, for a sort every step.
//
// Moves every field (built-in and extra, and the ids) so that the particle at
// old index order[i] ends at index i (a gather). Each field is gathered into one
// scratch array block by block (for_blocks: disjoint writes, deterministic) and
// swapped in, so the extra memory is one field, not a second particle set.
// Precondition (not checked, hot path): order is a permutation of 0..size()-1;
// the sorts that make it (parallel::RadixSort) guarantee it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>

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
    scratch_.resize(n);
    auto gather = [&](AlignedVector<Real>& field) {
      parallel::for_blocks("reorder", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
        const Real* from = field.data();
        Real* to = scratch_.data();
        for (std::size_t i = b; i < e; ++i) to[i] = from[order[i]];
      });
      field.swap(scratch_);
    };
    for (auto* v : {&p.position, &p.velocity, &p.acceleration, &p.acceleration_prev})
      for (int a = 0; a < 3; ++a) gather((*v)[a]);
    gather(p.mass);
    gather(p.density);
    gather(p.pressure);
    // Extra fields follow the 7 built-in ones in fields(), in creation order.
    const auto views = p.fields();
    for (std::size_t k = 0; k < p.extra_count(); ++k)
      for (int c = 0; c < views[7 + k].components; ++c) gather(p.extra(k, c));
    ids_.resize(n);
    parallel::for_blocks("reorder_ids", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) ids_[i] = p.id[order[i]];
    });
    p.id.swap(ids_);
  }

  // Bytes of scratch kept between calls.
  std::size_t bytes() const { return scratch_.capacity() * sizeof(Real) + ids_.capacity() * sizeof(std::uint64_t); }

 private:
  AlignedVector<Real> scratch_;
  AlignedVector<std::uint64_t> ids_;
};

}  // namespace swirl::spatial
