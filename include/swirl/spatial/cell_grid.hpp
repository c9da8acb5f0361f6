// SortedCellGrid<Real>: the neighbour search of the thesis's "future work"
// (chapter 6.2): particles sorted by cell in memory, so that the particles of
// a cell, and of a row of three cells, are contiguous.
//
// The grid is a view of the simulation's one particle order
// (spatial/particle_order.hpp): the order cuts space into cubic cells of
// length slightly more than h + s ((h + s)·(1 + 2⁻¹⁶): a pair that interacts in
// Real arithmetic, r² < h² after rounding, is then never two cells apart in
// any axis, however the cell index rounds, and stays so while no particle
// moved more than s/2 since the sort, the order's tolerance), sorts the
// particles by cell key — row-major (CellOrder::Rows) or the Morton prefix of
// the particle keys — and reorders every field. view() then only finds each
// cell's range in the sorted keys: a dense table of first particles per key
// when the key space (cells; Morton: 2^(3·bits per axis)) is at most
// 4·n + 4096, else a hash table of the occupied cells
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
#include "swirl/core/index_range.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/cell_order.hpp"
#include "swirl/spatial/occupied_cell_table.hpp"
#include "swirl/spatial/particle_order.hpp"

namespace swirl::spatial {

// The most contiguous ranges the 27 cells around a cell can take (9 with
// row-major keys: the three cells of a row are adjacent; 27 with Morton keys),
// and their holder.
inline constexpr std::size_t kMaxNeighbourRanges = 27;
using NeighbourRanges = std::array<IndexRange, kMaxNeighbourRanges>;

template <class Real>
class SortedCellGrid {
 public:
  // How index() finds the cells (Auto: dense when small enough, else hashed).
  void set_table(CellTable table) { table_ = table; }

  // The cell length a grid of support radius h and skin s asks the order for.
  static double cell_length_for(double h, double skin) { return (h + skin) * (1.0 + 1.0 / 65536.0); }

  // Indexes the cells of the order's current sort (the particles are in its
  // order). Returns false, having done nothing, when the order could not cut
  // the particles' box into cells (more than 2^21 per axis): the caller then
  // uses another search.
  bool view(const ParticleOrder<Real>& order, std::size_t block_size) {
    if (!order.valid() || !order.cells_fit() || !(order.request().cell_length > 0)) return false;
    view(order.frame(), order.keys(), {}, block_size);
    return true;
  }

  // The same view of particles that someone else put in a cell frame's key
  // order: f is a frame made for a cell request that fit
  // (ParticleOrder::frame_for), keys the particles' sorted keys in it. A
  // rank's particles with their ghosts (dist/halo.hpp) are a slice of the
  // global order with gaps: global_index[i] (increasing) is particle i's index
  // in that order, and neighbouring cells' ranges are merged only where they
  // are contiguous there, so that the ranges are the one-rank ones restricted
  // to the particles present (an explicit-SIMD pass starts a batch at each
  // range). Empty global_index: the particles are the whole order. keys and
  // global_index must outlive the view.
  void view(const KeyFrame& f, std::span<const std::uint64_t> keys, std::span<const std::uint64_t> global_index,
            std::size_t block_size) {
    if (!global_index.empty() && global_index.size() != keys.size())
      throw std::invalid_argument("cell grid: one global index per key is needed");
    global_ = global_index;
    n_ = keys.size();
    order_ = f.curve;
    cell_ = f.cell_length();
    dims_ = f.cells;
    unsigned key_bits = 0;
    if (order_ == CellOrder::Rows) {
      key_count_ = dims_[0] * dims_[1] * dims_[2];
      cell_keys_ = keys;
    } else {
      const std::uint64_t widest = std::max({dims_[0], dims_[1], dims_[2]});
      key_bits = 3 * std::max(1u, static_cast<unsigned>(std::bit_width(widest - 1)));
      key_count_ = std::uint64_t{1} << key_bits;
      if (f.cell_shift == 0) {
        cell_keys_ = keys;
      } else {
        shifted_.resize(n_);
        const unsigned shift = 3 * f.cell_shift;
        parallel::for_blocks_pinned("cell_keys", n_, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
          for (std::size_t i = b; i < e; ++i) shifted_[i] = keys[i] >> shift;
        });
        cell_keys_ = shifted_;
      }
    }
    dense_ = table_ == CellTable::Dense ||
             (table_ == CellTable::Auto && key_count_ <= 4 * static_cast<std::uint64_t>(n_) + 4096);
    if (dense_ && key_count_ > kMaxDenseKeys)
      throw std::invalid_argument("cell grid: a dense cell table (sph.grid.table = \"dense\") would need " +
                                  std::to_string(key_count_) + " entries, more than 2^31; use \"auto\" or \"hashed\"");
    index(block_size);
  }

  // Fills out with the ranges of the 27 cells around `key` (non-empty ones
  // only) and returns how many.
  int neighbour_ranges(std::uint64_t key, NeighbourRanges& out) const {
    return order_ == CellOrder::Rows ? row_ranges(key, out) : morton_ranges(key, out);
  }

  // The end of the cell that holds sorted index i (its last index + 1).
  std::uint32_t cell_end(std::uint32_t i) const { return cell_range(cell_keys_[i]).end; }

  // Sorted cell keys: keys()[i] is the cell of the particle now at index i.
  std::span<const std::uint64_t> keys() const { return cell_keys_; }
  std::size_t size() const { return n_; }
  double cell_length() const { return cell_; }
  CellOrder cell_order() const { return order_; }
  std::array<std::uint64_t, 3> dims() const { return dims_; }
  // Keys the dense table covers (cells with rows, 2^(3·bits) with Morton).
  std::uint64_t key_count() const { return key_count_; }
  bool dense() const { return dense_; }
  // Bytes kept between calls (shifted cell keys, cell table; the order's keys are the order's).
  std::size_t bytes() const {
    return shifted_.capacity() * sizeof(std::uint64_t) + start_.capacity() * sizeof(std::uint32_t) + hashed_.bytes();
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
  // order), one range each, merged where one ends where the next begins
  // (and, with global indices, where they are contiguous in the global order).
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
      const bool touches = count > 0 && out[static_cast<std::size_t>(count - 1)].end == b &&
                           (global_.empty() || global_[b - 1] + 1 == global_[b]);
      if (touches)
        out[static_cast<std::size_t>(count - 1)].end = e;
      else
        out[static_cast<std::size_t>(count++)] = {b, e};
    }
    return count;
  }

  // Finds each cell's range in the sorted cell keys.
  void index(std::size_t block_size) {
    const auto keys = cell_keys_;
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

  // The particles of one cell, [begin, end) (empty for an unoccupied cell).
  IndexRange cell_range(std::uint64_t key) const {
    if (dense_) return {start_[key], start_[key + 1]};
    const auto r = hashed_.range(key);
    return {r.begin, r.end};
  }

  std::size_t n_ = 0;
  CellOrder order_ = CellOrder::Rows;
  double cell_ = 1;
  std::uint64_t key_count_ = 1;  // the dense table's keys
  std::array<std::uint64_t, 3> dims_{1, 1, 1};
  bool dense_ = true;
  std::span<const std::uint64_t> global_;     // the particles' global indices (empty: the identity)
  std::span<const std::uint64_t> cell_keys_;  // the order's keys, or shifted_
  AlignedVector<std::uint64_t> shifted_;      // Morton cell keys when a cell is several key quanta
  std::vector<std::uint32_t> start_;  // dense: cells + 1 entries
  OccupiedCellTable hashed_;          // sparse: the occupied cells
  CellTable table_ = CellTable::Auto;
  static constexpr std::uint64_t kMaxDenseKeys = std::uint64_t{1} << 31;
};

// Compiled once, in src/spatial/cell_grid.cpp: users link the float and double copies
// instead of compiling them again.
extern template class SortedCellGrid<float>;
extern template class SortedCellGrid<double>;

}  // namespace swirl::spatial
