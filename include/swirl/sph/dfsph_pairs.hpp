// DfsphPairs<Real>: the neighbour pairs of one DFSPH evaluation, with
// m_j ∇W_ij, kept for the solves that follow it, and the two solve passes
// over them (dfsph_density_change and dfsph_pressure_velocity of
// sph/dfsph_passes.hpp, which stay as their slow twins).
//
// Why: a solve iteration runs both passes, and a step runs 4–100 iterations
// at fixed positions. Over the grid each pass visits every candidate of the
// neighbouring cells (about 6× the neighbours at h = one cell), tests its
// distance and evaluates the kernel's gradient again; 94 % of a DFSPH run's
// time went there (docs/performance.md, "Where swirl's DFSPH spends its
// time"). The evaluation's density pass finds the same pairs and computes the
// same m_j ∇W_ij anyway, so it records them here (Bender & Koschier's
// implementation precomputes the same per step); the solve passes then read
// one list per particle.
//
// Layout: for each particle i of the pass's range that is not a boundary
// particle, its neighbours j ≠ i with r_ij < h, in the grid's candidate
// order, as {j, ∇W's radial factor g(r_ij), r⃗_ij} (20 B a pair in float, 40 in
// double): the very values the grid passes compute, so the passes here
// evaluate the same expressions on the same operands. The lists
// of the particles of one block of the pass (block_size consecutive
// particles, the blocks of parallel::for_blocks_pinned) are one vector,
// filled and read by the block's own thread. A boundary particle has an
// empty list.
//
// Invariants: valid for the positions, masses and kinds of the evaluation
// that filled it, for the same range and block_size (the solve passes check
// both and throw std::logic_error otherwise). The sums go over each list in
// order, so the results are the same for any thread count, and for any rank
// count (the candidate order is the global key order), and they are the grid
// passes' bits (tests/sph/dfsph_pairs_test.cpp): keeping m_j ∇W_ij as one
// rounded vector (16 B) was tried first and changed results by rounding, which
// a DFSPH solve's stopping test turns into other iteration counts (the
// hydrostatic tank's pressure line moved from within 1 % to 1.9 %).
// Units: as dfsph_passes.hpp (g in 1/m⁵, r⃗ in m).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "swirl/core/index_range.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::sph {

template <class Real>
class DfsphPairs {
 public:
  struct Pair {
    std::uint32_t j;
    Real g;           // the kernel gradient's radial factor: ∇W_ij = g·r⃗_ij
    Real dx, dy, dz;  // r⃗_ij = x_i − x_j
  };

  // Makes room for the lists of `range` in blocks of block_size (keeping the
  // vectors' capacity from the last evaluation); every list starts empty.
  void prepare(IndexRange range, std::size_t block_size) {
    range_ = range;
    block_size_ = block_size;
    const std::size_t n = range.end - range.begin;
    end_.assign(n, 0);
    blocks_.resize(parallel::block_count(n, block_size));
    valid_ = true;
  }
  void clear() { valid_ = false; }
  bool valid() const { return valid_; }
  bool matches(IndexRange range, std::size_t block_size) const {
    return valid_ && range.begin == range_.begin && range.end == range_.end && block_size == block_size_;
  }

  // The vector of the block that starts at particle `first` of the range
  // (first = b·block_size, relative to the range), emptied: the filling pass's start of a block.
  std::vector<Pair>& start_block(std::size_t first) {
    std::vector<Pair>& list = blocks_[first / block_size_];
    list.clear();
    return list;
  }
  // Ends particle i's list (i relative to the range) at the block vector's current size.
  void end_list(std::size_t i, std::size_t size) { end_[i] = static_cast<std::uint32_t>(size); }

  // Particle i's list (i relative to the range), as [begin, end) of its block's vector.
  const Pair* begin(std::size_t i) const {
    const std::size_t first = i - i % block_size_;
    return blocks_[i / block_size_].data() + (i == first ? 0 : end_[i - 1]);
  }
  const Pair* end(std::size_t i) const { return blocks_[i / block_size_].data() + end_[i]; }

  std::size_t pairs() const {
    std::size_t total = 0;
    for (const auto& b : blocks_) total += b.size();
    return total;
  }
  std::size_t bytes() const {
    std::size_t total = end_.capacity() * sizeof(std::uint32_t);
    for (const auto& b : blocks_) total += b.capacity() * sizeof(Pair);
    return total;
  }

  void check(IndexRange range, std::size_t block_size) const {
    if (!matches(range, block_size))
      throw std::logic_error("DFSPH: a solve pass over pairs kept for another range or block size");
  }

 private:
  IndexRange range_{};
  std::size_t block_size_ = 1;
  bool valid_ = false;
  std::vector<std::uint32_t> end_;           // per particle of the range: its list's end in its block's vector
  std::vector<std::vector<Pair>> blocks_;    // per block of the range
};

// out[i] = (Dρ/Dt)_i = Σ_j m_j (v_i − v_j)·∇W_ij over i's kept pairs, for i in
// `range` (0 for a boundary particle).
template <class Real>
void dfsph_density_change(const DfsphPairs<Real>& pairs, const ParticleSet<Real>& p, std::size_t block_size, Real* out,
                          const std::int32_t* kind, IndexRange range) {
  pairs.check(range, block_size);
  const std::size_t from = range.begin;
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data(), *m = p.mass.data();
  parallel::for_blocks_pinned("dfsph_density_change", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = from + k;
      if (kind && is_boundary(kind[i])) {
        out[i] = 0;
        continue;
      }
      Real sum = 0;
      for (const auto* q = pairs.begin(k), *last = pairs.end(k); q != last; ++q) {
        const std::size_t j = q->j;
        const Real g = m[j] * q->g;  // as the grid pass: m_j ∇W_ij = g · r⃗_ij
        sum += g * ((vx[i] - vx[j]) * q->dx + (vy[i] - vy[j]) * q->dy + (vz[i] - vz[j]) * q->dz);
      }
      out[i] = sum;
    }
  });
}

// v_i −= Δt Σ_j (k_i + k_j) m_j ∇W_ij over i's kept pairs, k = κ/ρ per
// particle, for i in `range` (a boundary particle's velocity left alone).
// Reads no velocity, so writing v_i in place is safe.
template <class Real>
void dfsph_pressure_velocity(const DfsphPairs<Real>& pairs, ParticleSet<Real>& p, std::size_t block_size,
                             const Real* k_over_rho, Real dt, const std::int32_t* kind, IndexRange range) {
  pairs.check(range, block_size);
  const std::size_t from = range.begin;
  Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  const Real* m = p.mass.data();
  parallel::for_blocks_pinned("dfsph_pressure", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = from + k;
      if (kind && is_boundary(kind[i])) continue;
      const Real ki = k_over_rho[i];
      Real ax = 0, ay = 0, az = 0;
      for (const auto* q = pairs.begin(k), *last = pairs.end(k); q != last; ++q) {
        const std::size_t j = q->j;
        const Real g = m[j] * (ki + k_over_rho[j]) * q->g;  // as the grid pass
        ax += g * q->dx, ay += g * q->dy, az += g * q->dz;
      }
      vx[i] -= dt * ax;
      vy[i] -= dt * ay;
      vz[i] -= dt * az;
    }
  });
}

}  // namespace swirl::sph
