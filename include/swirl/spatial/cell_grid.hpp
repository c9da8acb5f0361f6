// SortedCellGrid<Real>: the neighbour search of the thesis's "future work"
// (chapter 6.2): particles sorted by cell and reordered in memory, so that the
// particles of a cell, and of a row of three cells, are contiguous.
//
// configure(order, skin): the cell order (spatial/cell_order.hpp: row-major,
// 9 ranges per cell, or Morton, up to 27) and the Verlet skin s ≥ 0 (m).
//
// sort(): the particles' bounding box is cut into cubic cells of length
// slightly more than h + s ((h + s)·(1 + 2⁻¹⁶): a pair that interacts in Real
// arithmetic, r² < h² after rounding, is then never two cells apart in any
// axis, however the cell index rounds, and stays so while no particle moved
// more than s/2 since the sort: spatial/skin_tracker.hpp). A cell's key is its
// row-major index (x fastest, then y, then z) or its Morton key; the
// (key, index) pairs go through the shared parallel LSD radix sort (stable:
// ties keep memory order). The caller then moves every particle field into key
// order (ParticleReorder) and calls index().
//
// index(): finds each cell's range in the sorted keys — a dense table of
// first particles per key when the key space (cells; Morton: 2^(3·bits per
// axis)) is at most 4·n + 4096, else a hash table of the occupied cells
// (spatial/occupied_cell_table.hpp: for scattered particles, no table
// proportional to the volume); set_table() can force either.
//
// neighbour_ranges(key): the contiguous index ranges holding every particle of
// the 27 cells around a cell, in increasing memory order: at most 9 with rows
// (the three cells x−1..x+1 of a row are adjacent keys, so one range), at most
// 27 with Morton (ranges that touch are merged).
//
// Invariant: scanning those ranges with spatial::within() finds exactly
// brute_force_pairs() (tested for both orders, including particles on cell
// faces and walls, and with a skin over many steps of moving particles).
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
#include <string>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/parallel/radix_sort.hpp"
#include "swirl/spatial/cell_order.hpp"
#include "swirl/spatial/occupied_cell_table.hpp"

namespace swirl::spatial {

// A half-open range [begin, end) of particle indices (sorted order).
struct IndexRange {
  std::uint32_t begin = 0, end = 0;
};

// The most contiguous ranges the 27 cells around a cell can take (9 with
// row-major keys: the three cells of a row are adjacent; 27 with Morton keys),
// and their holder.
inline constexpr std::size_t kMaxNeighbourRanges = 27;
using NeighbourRanges = std::array<IndexRange, kMaxNeighbourRanges>;

template <class Real>
class SortedCellGrid {
 public:
  // Cells per axis at most 2^21, so that a key fits 63 bits.
  static constexpr std::uint64_t kMaxCellsPerAxis = std::uint64_t{1} << 21;

  // The cell order and the skin s (m, finite, ≥ 0) of the next sort().
  void configure(CellOrder order, double skin) {
    if (!(skin >= 0) || !std::isfinite(skin)) throw std::invalid_argument("cell grid: skin must be finite and >= 0");
    order_ = order;
    skin_ = skin;
  }
  // How index() finds the cells (Auto: dense when small enough, else hashed).
  void set_table(CellTable table) { table_ = table; }

  // Computes every particle's cell key for support radius h (> 0) and sorts.
  // Returns false (and sorts nothing) when the particles spread over more than
  // kMaxCellsPerAxis cells in some axis: the caller then uses another search.
  // Throws on a non-finite position.
  bool sort(const ParticleSet<Real>& p, double h, std::size_t block_size) {
    if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("cell grid: h must be finite and > 0");
    const std::size_t n = p.size();
    if (n > 0xffffffffu) throw std::invalid_argument("cell grid: more than 2^32 - 1 particles");
    n_ = n;
    cell_ = (h + skin_) * (1.0 + 1.0 / 65536.0);
    inv_cell_ = 1.0 / cell_;
    if (!bounds(p, block_size)) return false;
    keys_.resize(n);
    parallel::for_blocks_pinned("cell_keys", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
      for (std::size_t i = b; i < e; ++i) keys_[i] = key_of(coordinate(x[i], 0), coordinate(y[i], 1), coordinate(z[i], 2));
    });
    unsigned key_bits = 0;
    if (order_ == CellOrder::Rows) {
      key_count_ = dims_[0] * dims_[1] * dims_[2];
      key_bits = std::max(1u, static_cast<unsigned>(std::bit_width(key_count_ - 1)));
    } else {
      const std::uint64_t widest = std::max({dims_[0], dims_[1], dims_[2]});
      key_bits = 3 * std::max(1u, static_cast<unsigned>(std::bit_width(widest - 1)));
      key_count_ = std::uint64_t{1} << key_bits;
    }
    dense_ = table_ == CellTable::Dense ||
             (table_ == CellTable::Auto && key_count_ <= 4 * static_cast<std::uint64_t>(n) + 4096);
    if (dense_ && key_count_ > kMaxDenseKeys)
      throw std::invalid_argument("cell grid: a dense cell table (sph.grid.table = \"dense\") would need " +
                                  std::to_string(key_count_) + " entries, more than 2^31; use \"auto\" or \"hashed\"");
    sort_.sort(keys_, key_bits);
    return true;
  }

  // order()[i]: the old index of the particle that goes to index i.
  std::span<const std::uint32_t> order() const { return sort_.order(); }

  // Builds the cell table; call after the particles were put in order().
  void index(std::size_t block_size) {
    const auto keys = sort_.keys();
    if (!dense_) {
      start_.clear();
      hashed_.build(keys, block_size);
      return;
    }
    hashed_.clear();
    const std::uint64_t cells = key_count_;
    start_.resize(cells + 1);
    // start_[k] = first sorted index with key ≥ k: particle i writes the
    // entries for the keys in (keys[i−1], keys[i]]; every entry is written once.
    parallel::for_blocks_pinned("cell_table", n_, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
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
    return order_ == CellOrder::Rows ? row_ranges(key, out) : morton_ranges(key, out);
  }

  // The end of the cell that holds sorted index i (its last index + 1).
  std::uint32_t cell_end(std::uint32_t i) const { return cell_range(sort_.keys()[i]).end; }

  // Sorted keys: keys()[i] is the cell of the particle now at index i.
  std::span<const std::uint64_t> keys() const { return sort_.keys(); }
  std::size_t size() const { return n_; }
  double cell_length() const { return cell_; }
  double skin() const { return skin_; }
  CellOrder cell_order() const { return order_; }
  std::array<std::uint64_t, 3> dims() const { return dims_; }
  // Keys the dense table covers (cells with rows, 2^(3·bits) with Morton).
  std::uint64_t key_count() const { return key_count_; }
  bool dense() const { return dense_; }
  // Bytes kept between calls (keys, sort buffers, cell table).
  std::size_t bytes() const {
    return keys_.capacity() * sizeof(std::uint64_t) + n_ * 2 * (sizeof(std::uint64_t) + sizeof(std::uint32_t)) +
           start_.capacity() * sizeof(std::uint32_t) + hashed_.bytes();
  }

 private:
  int row_ranges(std::uint64_t key, NeighbourRanges& out) const {
    const std::uint64_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
    const std::uint64_t cx = key % nx, rest = key / nx, cy = rest % ny, cz = rest / ny;
    const std::uint64_t x_lo = cx > 0 ? cx - 1 : 0, x_hi = std::min(cx + 1, nx - 1);
    int count = 0;
    for (std::uint64_t z = cz > 0 ? cz - 1 : 0; z <= std::min(cz + 1, nz - 1); ++z)
      for (std::uint64_t y = cy > 0 ? cy - 1 : 0; y <= std::min(cy + 1, ny - 1); ++y) {
        const std::uint64_t row = (z * ny + y) * nx;
        // The three cells are consecutive keys: their particles are one range.
        std::uint32_t b = 0, e = 0;
        if (dense_) {
          b = start_[row + x_lo];
          e = start_[row + x_hi + 1];
        } else {
          for (std::uint64_t x = x_lo; x <= x_hi; ++x) {
            const IndexRange c = cell_range(row + x);
            if (c.begin == c.end) continue;
            if (b == e) b = c.begin;
            e = c.end;
          }
        }
        if (b < e) out[static_cast<std::size_t>(count++)] = {b, e};
      }
    return count;
  }

  // The 27 cells' keys in increasing order (so the ranges come in memory
  // order), one range each, merged where one ends where the next begins.
  int morton_ranges(std::uint64_t key, NeighbourRanges& out) const {
    const std::uint64_t c[3] = {morton_compact(key), morton_compact(key >> 1), morton_compact(key >> 2)};
    std::uint64_t spread[3][3];
    int counts[3] = {0, 0, 0};
    for (int a = 0; a < 3; ++a)
      for (std::uint64_t v = c[a] > 0 ? c[a] - 1 : 0; v <= std::min(c[a] + 1, dims_[static_cast<std::size_t>(a)] - 1); ++v)
        spread[a][counts[a]++] = morton_spread(v) << a;
    std::array<std::uint64_t, 27> near{};
    int m = 0;
    for (int z = 0; z < counts[2]; ++z)
      for (int y = 0; y < counts[1]; ++y)
        for (int x = 0; x < counts[0]; ++x) {
          // Insertion into the sorted prefix: at most 27 keys.
          const std::uint64_t k = spread[0][x] | spread[1][y] | spread[2][z];
          int at = m++;
          for (; at > 0 && near[static_cast<std::size_t>(at - 1)] > k; --at)
            near[static_cast<std::size_t>(at)] = near[static_cast<std::size_t>(at - 1)];
          near[static_cast<std::size_t>(at)] = k;
        }
    int count = 0;
    for (int q = 0; q < m; ++q) {
      const std::uint64_t k = near[static_cast<std::size_t>(q)];
      const auto [b, e] = cell_range(k);
      if (b >= e) continue;
      if (count > 0 && out[static_cast<std::size_t>(count - 1)].end == b)
        out[static_cast<std::size_t>(count - 1)].end = e;
      else
        out[static_cast<std::size_t>(count++)] = {b, e};
    }
    return count;
  }

  // Bounding box (block-order reduction) and cells per axis.
  bool bounds(const ParticleSet<Real>& p, std::size_t block_size) {
    using MinMax = std::array<double, 6>;
    constexpr double inf = std::numeric_limits<double>::infinity();
    const MinMax init{inf, inf, inf, -inf, -inf, -inf};
    const MinMax box = parallel::reduce_blocks_pinned(
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
    return order_ == CellOrder::Rows ? (cz * dims_[1] + cy) * dims_[0] + cx : morton_key(cx, cy, cz);
  }

  // The particles of one cell, [begin, end) (empty for an unoccupied cell).
  IndexRange cell_range(std::uint64_t key) const {
    if (dense_) return {start_[key], start_[key + 1]};
    const auto r = hashed_.range(key);
    return {r.begin, r.end};
  }

  std::size_t n_ = 0;
  CellOrder order_ = CellOrder::Rows;
  double skin_ = 0;
  double cell_ = 1, inv_cell_ = 1;
  std::uint64_t key_count_ = 1;  // the dense table's keys
  std::array<double, 3> lo_{};
  std::array<std::uint64_t, 3> dims_{1, 1, 1};
  bool dense_ = true;
  AlignedVector<std::uint64_t> keys_;  // per particle, in the order before sorting
  parallel::RadixSort<std::uint64_t> sort_;
  std::vector<std::uint32_t> start_;  // dense: cells + 1 entries
  OccupiedCellTable hashed_;          // sparse: the occupied cells
  CellTable table_ = CellTable::Auto;
  static constexpr std::uint64_t kMaxDenseKeys = std::uint64_t{1} << 31;
};

}  // namespace swirl::spatial
