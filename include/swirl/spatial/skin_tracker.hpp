// SkinTracker<Real>: decides when a SortedCellGrid built with a Verlet skin s
// (cells of side h + s, spatial/cell_grid.hpp) must be sorted again.
//
// remember(p) keeps every particle's position and id right after a sort (in
// the sorted order). must_resort(p, s) is false only while the particles are
// the same ones in the same memory order (same count, same ids) and none moved
// more than s/2 from where it was remembered: then two particles now closer
// than h were closer than h + s at the sort, hence in adjacent cells, and the
// old cell ranges still hold every neighbour (no missed pair: tested against
// brute force over many steps). Anything else (a first call, particles added,
// removed or reordered by someone else) asks for a sort.
//
// The largest displacement is a reduce_blocks max (a max is exact, so the
// answer is the same for any thread count). Units: metres.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "swirl/core/aligned.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::spatial {

template <class Real>
class SkinTracker {
 public:
  void remember(const ParticleSet<Real>& p, std::size_t block_size) {
    const std::size_t n = p.size();
    for (auto* v : {&x_, &y_, &z_}) v->resize(n);
    ids_.resize(n);
    parallel::for_blocks_pinned("skin_remember", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      std::copy(p.position.x.data() + b, p.position.x.data() + e, x_.data() + b);
      std::copy(p.position.y.data() + b, p.position.y.data() + e, y_.data() + b);
      std::copy(p.position.z.data() + b, p.position.z.data() + e, z_.data() + b);
      std::copy(p.id.data() + b, p.id.data() + e, ids_.data() + b);
    });
    valid_ = true;
  }

  // Forgets the remembered state: the next must_resort() is true.
  void forget() { valid_ = false; }

  // The largest displacement since remember(), squared (m²), computed in
  // double; infinity when the particles are not the remembered ones.
  double max_displacement2(const ParticleSet<Real>& p, std::size_t block_size) const {
    constexpr double kDifferent = std::numeric_limits<double>::infinity();
    if (!valid_ || p.size() != ids_.size()) return kDifferent;
    return parallel::reduce_blocks_pinned(
        "skin_displacement", p.size(), block_size, 0.0,
        [&](std::size_t b, std::size_t e) {
          const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
          const std::uint64_t* id = p.id.data();
          double worst = 0;
          bool same = true;
          for (std::size_t i = b; i < e; ++i) {
            const double dx = double(x[i]) - double(x_[i]), dy = double(y[i]) - double(y_[i]),
                         dz = double(z[i]) - double(z_[i]);
            const double d2 = dx * dx + dy * dy + dz * dz;
            worst = std::max(worst, d2);
            // A non-finite position also asks for a sort, whose bounds check reports it.
            same &= id[i] == ids_[i] && d2 < kDifferent;
          }
          return same ? worst : kDifferent;
        },
        [](double a, double b) { return std::max(a, b); });
  }

  bool must_resort(const ParticleSet<Real>& p, double skin, std::size_t block_size) const {
    const double half = 0.5 * skin;
    return !(max_displacement2(p, block_size) <= half * half);
  }

  std::size_t bytes() const { return (x_.capacity() + y_.capacity() + z_.capacity()) * sizeof(Real) +
                                     ids_.capacity() * sizeof(std::uint64_t); }

 private:
  AlignedVector<Real> x_, y_, z_;
  AlignedVector<std::uint64_t> ids_;
  bool valid_ = false;
};

}  // namespace swirl::spatial
