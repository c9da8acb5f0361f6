// SortedCellGrid<Real>: the neighbour search of the thesis's "future work"
// (chapter 6.2): particles sorted by cell and reordered in memory, so that the
// particles of a cell, and of a row of three cells, are contiguous.
//
// sort(): the particles' bounding box is cut into cubic cells of length
// slightly more than h (h·(1 + 2⁻¹⁶): a pair that interacts in Real arithmetic,
// r² < h² after rounding, is then never two cells apart in any axis, however
// the cell index rounds). A cell's key is its row-major index
// (x fastest, then y, then z); the (key, index) pairs go through the shared
// parallel LSD radix sort (stable: ties keep memory order). The caller then
// moves every particle field into key order (ParticleReorder) and calls index().
//
// index(): finds each cell's range in the sorted keys — a dense table of
// first particles per cell when the box has at most 4·n + 4096 cells, else a
// binary search in the sorted keys (sparse, for scattered particles: no table
// proportional to the volume).
//
// neighbour_ranges(key): the up to 9 contiguous index ranges holding every
// particle of the 27 cells around a cell (the three cells x−1..x+1 of a row are
// adjacent keys, so one range), in increasing memory order.
//
// Invariant: scanning those ranges with spatial::within() finds exactly
// brute_force_pairs() (tested, including particles on cell faces and walls).
// Every result depends on positions and memory order only, never on threads.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/parallel/radix_sort.hpp"

namespace swirl::spatial {

// A half-open range [begin, end) of particle indices (sorted order).
struct IndexRange {
  std::uint32_t begin = 0, end = 0;
};

// The most contiguous ranges the 27 cells around a cell can take (9 with
// row-major keys: the three cells of a row are adjacent), and their holder.
inline constexpr std::size_t kMaxNeighbourRanges = 9;
using NeighbourRanges = std::array<IndexRange, kMaxNeighbourRanges>;

template <class Real>
class SortedCellGrid {
 public:
  // Cells per axis at most 2^21, so that a key fits 63 bits.
  static constexpr std::uint64_t kMaxCellsPerAxis = std::uint64_t{1} << 21;

  // Computes every particle's cell key for support radius h (> 0) and sorts.
  // Returns false (and sorts nothing) when the particles spread over more than
  // kMaxCellsPerAxis cells in some axis: the caller then uses another search.
  // Throws on a non-finite position.
  bool sort(const ParticleSet<Real>& p, double h, std::size_t block_size) {
    if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("cell grid: h must be finite and > 0");
    const std::size_t n = p.size();
    if (n > 0xffffffffu) throw std::invalid_argument("cell grid: more than 2^32 - 1 particles");
    n_ = n;
    cell_ = h * (1.0 + 1.0 / 65536.0);
    inv_cell_ = 1.0 / cell_;
    if (!bounds(p, block_size)) return false;
    keys_.resize(n);
    parallel::for_blocks("cell_keys", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
      for (std::size_t i = b; i < e; ++i) keys_[i] = key_of(coordinate(x[i], 0), coordinate(y[i], 1), coordinate(z[i], 2));
    });
    const std::uint64_t cells = dims_[0] * dims_[1] * dims_[2];
    const unsigned key_bits = std::max(1u, static_cast<unsigned>(std::bit_width(cells - 1)));
    sort_.sort(keys_, key_bits);
    dense_ = cells <= 4 * static_cast<std::uint64_t>(n) + 4096;
    return true;
  }

  // order()[i]: the old index of the particle that goes to index i.
  std::span<const std::uint32_t> order() const { return sort_.order(); }

  // Builds the cell table; call after the particles were put in order().
  void index(std::size_t block_size) {
    const auto keys = sort_.keys();
    if (!dense_) {
      start_.clear();
      return;
    }
    const std::uint64_t cells = dims_[0] * dims_[1] * dims_[2];
    start_.resize(cells + 1);
    // start_[k] = first sorted index with key ≥ k: particle i writes the
    // entries for the keys in (keys[i−1], keys[i]]; every entry is written once.
    parallel::for_blocks("cell_table", n_, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        const std::uint64_t from = i == 0 ? 0 : keys[i - 1] + 1;
        for (std::uint64_t k = from; k <= keys[i]; ++k) start_[k] = static_cast<std::uint32_t>(i);
        if (i + 1 == n_)  // the empty cells after the last particle, and the end
          for (std::uint64_t k = keys[i] + 1; k <= cells; ++k) start_[k] = static_cast<std::uint32_t>(n_);
      }
    });
    if (n_ == 0) std::fill(start_.begin(), start_.end(), 0u);
  }

  // Fills out with the ranges of the 27 cells around `key` (non-empty ones
  // only) and returns how many.
  int neighbour_ranges(std::uint64_t key, NeighbourRanges& out) const {
    const std::uint64_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
    const std::uint64_t cx = key % nx, rest = key / nx, cy = rest % ny, cz = rest / ny;
    const std::uint64_t x_lo = cx > 0 ? cx - 1 : 0, x_hi = std::min(cx + 1, nx - 1);
    int count = 0;
    for (std::uint64_t z = cz > 0 ? cz - 1 : 0; z <= std::min(cz + 1, nz - 1); ++z)
      for (std::uint64_t y = cy > 0 ? cy - 1 : 0; y <= std::min(cy + 1, ny - 1); ++y) {
        const std::uint64_t row = (z * ny + y) * nx;
        const std::uint32_t b = first_at_or_after(row + x_lo), e = first_at_or_after(row + x_hi + 1);
        if (b < e) out[static_cast<std::size_t>(count++)] = {b, e};
      }
    return count;
  }

  // The end of the cell that holds sorted index i (its last index + 1).
  std::uint32_t cell_end(std::uint32_t i) const { return first_at_or_after(sort_.keys()[i] + 1); }

  // Sorted keys: keys()[i] is the cell of the particle now at index i.
  std::span<const std::uint64_t> keys() const { return sort_.keys(); }
  std::size_t size() const { return n_; }
  double cell_length() const { return cell_; }
  std::array<std::uint64_t, 3> dims() const { return dims_; }
  bool dense() const { return dense_; }
  // Bytes kept between calls (keys, sort buffers, cell table).
  std::size_t bytes() const {
    return keys_.capacity() * sizeof(std::uint64_t) + n_ * 2 * (sizeof(std::uint64_t) + sizeof(std::uint32_t)) +
           start_.capacity() * sizeof(std::uint32_t);
  }

 private:
  // Bounding box (block-order reduction) and cells per axis.
  bool bounds(const ParticleSet<Real>& p, std::size_t block_size) {
    using MinMax = std::array<double, 6>;
    constexpr double inf = std::numeric_limits<double>::infinity();
    const MinMax init{inf, inf, inf, -inf, -inf, -inf};
    const MinMax box = parallel::reduce_blocks(
        "cell_bounds", p.size(), block_size, init,
        [&](std::size_t b, std::size_t e) {
          MinMax m = init;
          for (int a = 0; a < 3; ++a) {
            const Real* x = p.position[a].data();
            for (std::size_t i = b; i < e; ++i) {
              const double v = static_cast<double>(x[i]);
              if (!std::isfinite(v)) throw std::runtime_error("cell grid: a particle position is not finite");
              m[static_cast<std::size_t>(a)] = std::min(m[static_cast<std::size_t>(a)], v);
              m[static_cast<std::size_t>(a) + 3] = std::max(m[static_cast<std::size_t>(a) + 3], v);
            }
          }
          return m;
        },
        [](MinMax a, const MinMax& b) {
          for (std::size_t k = 0; k < 3; ++k) {
            a[k] = std::min(a[k], b[k]);
            a[k + 3] = std::max(a[k + 3], b[k + 3]);
          }
          return a;
        });
    for (std::size_t a = 0; a < 3; ++a) {
      lo_[a] = p.empty() ? 0.0 : box[a];
      const double extent = p.empty() ? 0.0 : (box[a + 3] - box[a]) * inv_cell_;
      if (!(extent < static_cast<double>(kMaxCellsPerAxis - 1))) return false;
      dims_[a] = static_cast<std::uint64_t>(std::floor(extent)) + 1;
    }
    return true;
  }

  std::uint64_t coordinate(Real x, std::size_t axis) const {
    const double c = std::floor((static_cast<double>(x) - lo_[axis]) * inv_cell_);
    return std::min(static_cast<std::uint64_t>(std::max(c, 0.0)), dims_[axis] - 1);
  }
  std::uint64_t key_of(std::uint64_t cx, std::uint64_t cy, std::uint64_t cz) const {
    return (cz * dims_[1] + cy) * dims_[0] + cx;
  }

  std::uint32_t first_at_or_after(std::uint64_t key) const {
    if (dense_) return start_[key];
    const auto keys = sort_.keys();
    return static_cast<std::uint32_t>(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
  }

  std::size_t n_ = 0;
  double cell_ = 1, inv_cell_ = 1;
  std::array<double, 3> lo_{};
  std::array<std::uint64_t, 3> dims_{1, 1, 1};
  bool dense_ = true;
  AlignedVector<std::uint64_t> keys_;  // per particle, in the order before sorting
  parallel::RadixSort<std::uint64_t> sort_;
  std::vector<std::uint32_t> start_;  // dense: cells + 1 entries
};

}  // namespace swirl::spatial
