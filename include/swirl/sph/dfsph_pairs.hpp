// DfsphPairs<Real>: the neighbour pairs of one DFSPH evaluation, with their
// kernel gradient's radial factor, kept for the solves that follow it, and the two solve passes
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
// order, as j and ∇W's radial factor g(r_ij) (8 B a pair in float, 12 in
// double), in two arrays per block: the lists of the particles of one block
// of the pass (block_size consecutive particles, the blocks of
// parallel::for_blocks_pinned), filled and read by the block's own thread. A
// boundary particle has an empty list. r⃗_ij is not kept: the passes compute
// x_i − x_j again from the positions, which is the density pass's own
// subtraction, so they evaluate the grid passes' expressions on the same
// operands. (Keeping r⃗_ij, 20 B a pair, was the first layout; reading 2.5×
// fewer bytes made no difference on its own, because the scalar loop was
// bound by its nine loads a pair, not by memory bandwidth:
// docs/performance/dfsph.md.)
//
// The passes (KernelPath, from sph.grid.simd): Scalar is one pair at a time
// per particle, two particles' lists side by side (each sum is one chain of
// multiply-adds in its list's order; two chains keep the FMA unit busy);
// Simd, in float, runs sph/dfsph_pair_kernels.hpp's per-instruction-set
// bodies on particles packed as {z, x, y, m} and {v_z, v_x, v_y, 0} (16 B
// each, kept here: the positions packed once per filling, the velocities at
// every density-change pass), reading a neighbour with one or two vector loads
// instead of seven scalar ones; in double Simd runs the scalar loops. Every
// multiply-add is spelled out (sph/dfsph_terms.hpp), so that both paths and
// the grid twins round alike: the same bits where the build's scalar code
// and the SIMD copy both fuse (or both do not: the SSE2 copy never does).
//
// Invariants: valid for the positions, masses and kinds of the evaluation
// that filled it, for the same range and block_size (the solve passes check
// both and throw std::logic_error otherwise; the positions are read again, so
// they must not change between the filling and the solves — the stepper moves
// particles only after its density solve and then evaluates again). The sums
// go over each list in order, so the results are the same for any thread
// count, and for any rank count (the candidate order is the global key
// order), and they are the grid passes' bits (tests/sph/dfsph_pairs_test.cpp):
// keeping m_j ∇W_ij as one rounded vector (16 B) was tried first and changed
// results by rounding, which a DFSPH solve's stopping test turns into other
// iteration counts (the hydrostatic tank's pressure line moved from within 1 %
// to 1.9 %).
// Units: as dfsph_passes.hpp (g in 1/m⁵, r⃗ in m).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/core/index_range.hpp"
#include "swirl/core/kernel_path.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sph/dfsph_pair_kernels.hpp"
#include "swirl/sph/dfsph_terms.hpp"

namespace swirl::sph {

template <class Real>
class DfsphPairs {
 public:
  // One block's lists, one after the other, as two arrays (a pair is j[q], g[q]).
  class Block {
   public:
    void clear() {
      j_.clear();
      g_.clear();
    }
    void push_back(std::uint32_t j, Real g) {
      j_.push_back(j);
      g_.push_back(g);
    }
    std::size_t size() const { return j_.size(); }
    const std::uint32_t* j() const { return j_.data(); }
    const Real* g() const { return g_.data(); }
    std::size_t bytes() const { return j_.capacity() * sizeof(std::uint32_t) + g_.capacity() * sizeof(Real); }

   private:
    std::vector<std::uint32_t> j_;  // the neighbour's index
    std::vector<Real> g_;           // the kernel gradient's radial factor: ∇W_ij = g·r⃗_ij
  };
  // Particle i's list: its neighbours j[0, size) and their g[0, size).
  struct List {
    const std::uint32_t* j;
    const Real* g;
    std::size_t size;
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
    positions_packed_ = false;
  }
  void clear() { valid_ = false; }
  bool valid() const { return valid_; }
  bool matches(IndexRange range, std::size_t block_size) const {
    return valid_ && range.begin == range_.begin && range.end == range_.end && block_size == block_size_;
  }

  // The lists of the block that starts at particle `first` of the range
  // (first = b·block_size, relative to the range), emptied: the filling pass's start of a block.
  Block& start_block(std::size_t first) {
    Block& block = blocks_[first / block_size_];
    block.clear();
    return block;
  }
  // Ends particle i's list (i relative to the range) at the block's current size.
  void end_list(std::size_t i, std::size_t size) { end_[i] = static_cast<std::uint32_t>(size); }

  // Particle i's list (i relative to the range).
  List list(std::size_t i) const {
    const Block& block = blocks_[i / block_size_];
    const std::size_t begin = i % block_size_ == 0 ? 0 : end_[i - 1];
    return {block.j() + begin, block.g() + begin, end_[i] - begin};
  }

  std::size_t pairs() const {
    std::size_t total = 0;
    for (const auto& b : blocks_) total += b.size();
    return total;
  }
  std::size_t bytes() const {
    std::size_t total = end_.capacity() * sizeof(std::uint32_t);
    total += (packed_xm_.capacity() + packed_v_.capacity()) * sizeof(float);
    for (const auto& b : blocks_) total += b.bytes();
    return total;
  }

  // ---- For the SIMD passes (float; sph/dfsph_pair_kernels.hpp) ----
  // Block b's lists (b relative to the range's blocks).
  PairBlock block(std::size_t b) const
    requires std::is_same_v<Real, float>
  {
    const std::size_t first = b * block_size_;
    const std::size_t count = std::min(block_size_, std::size_t(range_.end - range_.begin) - first);
    return {end_.data() + first, blocks_[b].j(), blocks_[b].g(), count};
  }
  // Packs every particle of p: {z, x, y, m} once per filling (the solves do not
  // move particles or change masses), {v_z, v_x, v_y, 0} at every call with velocities.
  PackedParticles pack(const ParticleSet<Real>& p, std::size_t block_size, bool velocities)
    requires std::is_same_v<Real, float>
  {
    const std::size_t n = p.size();
    const float *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
    const float *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
    const bool positions = !positions_packed_ || packed_xm_.size() != 4 * n;
    if (!positions && !velocities) return {packed_xm_.data(), packed_v_.data()};
    if (positions) packed_xm_.resize(4 * n);
    if (velocities) packed_v_.resize(4 * n);
    float *xm = packed_xm_.data(), *v = packed_v_.data();
    parallel::for_blocks_pinned("dfsph_pack", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      if (positions)
        for (std::size_t i = b; i < e; ++i) {
          xm[4 * i] = z[i], xm[4 * i + 1] = x[i], xm[4 * i + 2] = y[i], xm[4 * i + 3] = m[i];
        }
      if (velocities)
        for (std::size_t i = b; i < e; ++i) {
          v[4 * i] = vz[i], v[4 * i + 1] = vx[i], v[4 * i + 2] = vy[i], v[4 * i + 3] = 0;
        }
    });
    positions_packed_ = true;
    return {packed_xm_.data(), packed_v_.data()};
  }
  // What a pair costs: 8 B in float, 12 in double (sim/footprint.hpp counts it).
  static constexpr std::size_t kBytesPerPair = sizeof(std::uint32_t) + sizeof(Real);

  void check(IndexRange range, std::size_t block_size) const {
    if (!matches(range, block_size))
      throw std::logic_error("DFSPH: a solve pass over pairs kept for another range or block size");
  }

 private:
  IndexRange range_{};
  std::size_t block_size_ = 1;
  bool valid_ = false;
  std::vector<std::uint32_t> end_;  // per particle of the range: its list's end in its block
  std::vector<Block> blocks_;       // per block of the range
  // The SIMD passes' packed particles (float only; empty otherwise).
  AlignedVector<float> packed_xm_, packed_v_;
  bool positions_packed_ = false;
};

namespace detail {

// Calls one(k) or two(k, l) for the particles k of [b, e) that are not
// boundary particles (boundary(k) says which are), two at a time while there
// are two; two(k, l) runs the particles' lists side by side.
template <class Boundary, class One, class Two>
inline void fluid_in_twos(std::size_t b, std::size_t e, Boundary&& boundary, One&& one, Two&& two) {
  std::size_t waiting = e;  // a fluid particle without its partner yet (e: none)
  for (std::size_t k = b; k < e; ++k) {
    if (boundary(k)) continue;
    if (waiting == e) {
      waiting = k;
    } else {
      two(waiting, k);
      waiting = e;
    }
  }
  if (waiting != e) one(waiting);
}

// Calls first(q) for q < n and second(q) for q < n2, each in its order, the
// two interleaved while both last: two independent chains of FMAs in flight.
template <class First, class Second>
inline void side_by_side(std::size_t n, std::size_t n2, First&& first, Second&& second) {
  const std::size_t both = n < n2 ? n : n2;
  for (std::size_t q = 0; q < both; ++q) {
    first(q);
    second(q);
  }
  for (std::size_t q = both; q < n; ++q) first(q);
  for (std::size_t q = both; q < n2; ++q) second(q);
}

}  // namespace detail

// out[i] = (Dρ/Dt)_i = Σ_j m_j (v_i − v_j)·∇W_ij over i's kept pairs, for i in
// `range` (0 for a boundary particle).
//
// Why two particles at a time: each particle's sum is one chain of FMAs
// (its list's order: the grid pass's bits), so one list alone runs at the
// FMA's latency per pair; two lists side by side keep two chains in flight.
template <class Real>
void dfsph_density_change(DfsphPairs<Real>& pairs, const ParticleSet<Real>& p, std::size_t block_size, Real* out,
                          const std::int32_t* kind, IndexRange range, KernelPath path) {
  pairs.check(range, block_size);
  const std::size_t from = range.begin;
  if constexpr (std::is_same_v<Real, float>) {
    if (path == KernelPath::Simd) {
      const PackedParticles packed = pairs.pack(p, block_size, true);
      parallel::for_blocks_pinned("dfsph_density_change", range.end - range.begin, block_size,
                                  [&](std::size_t b, std::size_t, std::size_t) {
        dfsph_change_block_simd(packed, pairs.block(b / block_size), from + b, kind, out);
      });
      return;
    }
  }
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data(), *m = p.mass.data();
  // Particle i's sum after its pair q of `list` (r⃗_ij as the density pass found it, x_i − x_j).
  const auto add = [&](Real sum, std::size_t i, const typename DfsphPairs<Real>::List& list, std::size_t q) {
    const std::size_t j = list.j[q];
    const Real g = m[j] * list.g[q];  // as the grid pass: m_j ∇W_ij = g · r⃗_ij
    return detail::density_change_term(sum, g, vx[i] - vx[j], vy[i] - vy[j], vz[i] - vz[j], x[i] - x[j],
                                       y[i] - y[j], z[i] - z[j]);
  };
  parallel::for_blocks_pinned("dfsph_density_change", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const auto boundary = [&](std::size_t k) {
      if (!kind || !is_boundary(kind[from + k])) return false;
      out[from + k] = 0;
      return true;
    };
    const auto one = [&](std::size_t k) {
      const std::size_t i = from + k;
      const auto list = pairs.list(k);
      Real sum = 0;
      for (std::size_t q = 0; q < list.size; ++q) sum = add(sum, i, list, q);
      out[i] = sum;
    };
    const auto two = [&](std::size_t k, std::size_t l) {
      const std::size_t i = from + k, i2 = from + l;
      const auto list = pairs.list(k), list2 = pairs.list(l);
      Real sum = 0, sum2 = 0;
      detail::side_by_side(list.size, list2.size, [&](std::size_t q) { sum = add(sum, i, list, q); },
                           [&](std::size_t q) { sum2 = add(sum2, i2, list2, q); });
      out[i] = sum;
      out[i2] = sum2;
    };
    detail::fluid_in_twos(b, e, boundary, one, two);
  });
}

// v_i −= Δt Σ_j (k_i + k_j) m_j ∇W_ij over i's kept pairs, k = κ/ρ per
// particle, for i in `range` (a boundary particle's velocity left alone);
// two particles at a time, as dfsph_density_change.
// Reads no velocity, so writing v_i in place is safe.
template <class Real>
void dfsph_pressure_velocity(DfsphPairs<Real>& pairs, ParticleSet<Real>& p, std::size_t block_size,
                             const Real* k_over_rho, Real dt, const std::int32_t* kind, IndexRange range,
                             KernelPath path) {
  pairs.check(range, block_size);
  const std::size_t from = range.begin;
  if constexpr (std::is_same_v<Real, float>) {
    if (path == KernelPath::Simd) {
      const PackedParticles packed = pairs.pack(p, block_size, false);
      parallel::for_blocks_pinned("dfsph_pressure", range.end - range.begin, block_size,
                                  [&](std::size_t b, std::size_t, std::size_t) {
        dfsph_pressure_block_simd(packed, pairs.block(b / block_size), from + b, kind, k_over_rho, dt,
                                  p.velocity.x.data(), p.velocity.y.data(), p.velocity.z.data());
      });
      return;
    }
  }
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  struct Sum {
    Real x = 0, y = 0, z = 0;
  };
  // Particle i's sum (with its k_i) after its pair q of `list`.
  const auto add = [&](Sum& a, std::size_t i, Real ki, const typename DfsphPairs<Real>::List& list, std::size_t q) {
    const std::size_t j = list.j[q];
    const Real g = m[j] * (ki + k_over_rho[j]) * list.g[q];  // as the grid pass
    a.x = detail::fused(g, x[i] - x[j], a.x);
    a.y = detail::fused(g, y[i] - y[j], a.y);
    a.z = detail::fused(g, z[i] - z[j], a.z);
  };
  const auto apply = [&](std::size_t i, const Sum& a) {  // v_i − Δt·a, fused as the grid pass
    vx[i] = detail::fused(-dt, a.x, vx[i]);
    vy[i] = detail::fused(-dt, a.y, vy[i]);
    vz[i] = detail::fused(-dt, a.z, vz[i]);
  };
  parallel::for_blocks_pinned("dfsph_pressure", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const auto boundary = [&](std::size_t k) { return kind && is_boundary(kind[from + k]); };
    const auto one = [&](std::size_t k) {
      const std::size_t i = from + k;
      const auto list = pairs.list(k);
      const Real ki = k_over_rho[i];
      Sum a;
      for (std::size_t q = 0; q < list.size; ++q) add(a, i, ki, list, q);
      apply(i, a);
    };
    const auto two = [&](std::size_t k, std::size_t l) {
      const std::size_t i = from + k, i2 = from + l;
      const auto list = pairs.list(k), list2 = pairs.list(l);
      const Real ki = k_over_rho[i], ki2 = k_over_rho[i2];
      Sum a, a2;
      detail::side_by_side(list.size, list2.size, [&](std::size_t q) { add(a, i, ki, list, q); },
                           [&](std::size_t q) { add(a2, i2, ki2, list2, q); });
      apply(i, a);
      apply(i2, a2);
    };
    detail::fluid_in_twos(b, e, boundary, one, two);
  });
}

}  // namespace swirl::sph
