// SpatialHash<Real>: the thesis's neighbour search (section 4.2).
//
// build(): every particle gets its cell (floor(x / h)) and the Teschner hash of
// that cell into M buckets; the table is then built by a stable counting sort
// (count, prefix sum into the offset table, scatter — in parallel, where the
// thesis ran it serially), and the positions are copied into bucket order as
// the thesis's table holds them.
//
// find_neighbours(): for every particle, in bucket order (the thesis walks the
// table bucket by bucket, Algorithm 4), all 27 cells around its cell are
// hashed and their buckets scanned. A particle found in a scanned bucket whose
// cell is not the searched one is there by a hash collision, and the duplicate
// check (DuplicateCheck) drops it, which also drops the duplicate interactions
// that arise when two of the 27 cells share a bucket. Where the check runs is
// a choice: BeforeDistance (ours, the default) compares the cells first and
// skips the distance test of a collision; AfterDistance (the thesis's place,
// section 4.2.3: "in addition to checking distances ... their grid cell
// relation must be tested") tests the distance first and the cells of the
// pairs within h. Both give the same pairs. Off (the thesis's faster option)
// keeps every pair within h, so duplicates can appear. Interaction lists are CSR (NeighbourList), one row per
// particle in bucket order, neighbours in scan order: deterministic for any
// thread count.
//
// The 26 neighbour cells' buckets (NeighbourHashes): hashed by the search as
// it scans them (ours, OnTheFly), or precomputed by build() into 26 hashes per
// particle that the search reads (the thesis's, section 4.2.3; its Figure 5.2
// and section 4.5 count this "neighbour hashing" as a pass of its own, timed
// here as "forces.neighbour_hashes"). The thesis's SPEs ran that pass while
// the PPE built the table; ours runs it after the table build, on every thread.
// The buckets are the same, so the lists are the same either way (tested).
//
// Invariant: with the check on, the interactions are exactly the pairs of
// brute_force_pairs() (tested).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/core/phase_timers.hpp"
#include "swirl/parallel/counting_sort.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/distance.hpp"
#include "swirl/spatial/hash_options.hpp"
#include "swirl/spatial/neighbour_list.hpp"
#include "swirl/spatial/teschner_hash.hpp"

namespace swirl::spatial {


// What a search saw, for the thesis's Table 5.2.
struct SearchCounters {
  std::uint64_t tests = 0;            // candidate pairs (i, j ≠ i) taken from scanned buckets
  std::uint64_t redundant_tests = 0;  // of which j's cell is not the searched cell (hash collisions)
  std::uint64_t interactions = 0;     // pairs put in the lists

  SearchCounters& operator+=(const SearchCounters& o) {
    tests += o.tests;
    redundant_tests += o.redundant_tests;
    interactions += o.interactions;
    return *this;
  }
};

template <class Real>
class SpatialHash {
 public:
  // Hashes the particles with cell length h (> 0) into `buckets` (≥ 1) buckets
  // and builds the table (its counting sort on one thread with TableBuild::Serial;
  // the same table). With NeighbourHashes::Precomputed it also writes the 26
  // neighbour-cell hashes of every particle for the next find_neighbours().
  // With timers, the sort is the phase "forces.table" and the neighbour
  // hashes "forces.neighbour_hashes".
  void build(const ParticleSet<Real>& p, Real h, std::uint32_t buckets, std::size_t block_size,
             TableBuild table = TableBuild::Parallel, NeighbourHashes neighbour_hashes = NeighbourHashes::OnTheFly,
             PhaseTimers* timers = nullptr) {
    if (!(h > Real(0))) throw std::invalid_argument("spatial hash: cell length must be > 0");
    if (buckets == 0) throw std::invalid_argument("spatial hash: at least one bucket");
    h_ = h;
    const std::size_t n = p.size();
    cells_.resize(n);
    hashes_.resize(n);
    parallel::for_blocks("hash_particles", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        cells_[i] = cell_of(p.position.x[i], p.position.y[i], p.position.z[i], h);
        hashes_[i] = hash_cell(cells_[i], buckets);
      }
    });
    {
      std::optional<ScopedPhase> phase;
      if (timers) phase.emplace(*timers, "forces.table");
      sort_.sort(hashes_, buckets, table == TableBuild::Serial);
    }
    const auto& order = sort_.order();
    for (int axis = 0; axis < 3; ++axis) sorted_position_[axis].resize(n);
    sorted_cells_.resize(n);
    parallel::for_blocks("fill_table", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t slot = b; slot < e; ++slot) sorted_cells_[slot] = cells_[order[slot]];
      for (int axis = 0; axis < 3; ++axis) {
        const Real* x = p.position[axis].data();
        Real* s = sorted_position_[axis].data();
        for (std::size_t slot = b; slot < e; ++slot) s[slot] = x[order[slot]];
      }
    });
    neighbour_hashes_mode_ = neighbour_hashes;
    if (neighbour_hashes == NeighbourHashes::Precomputed) {
      std::optional<ScopedPhase> phase;
      if (timers) phase.emplace(*timers, "forces.neighbour_hashes");
      precompute_neighbour_hashes(buckets, block_size);
    } else {
      neighbour_hashes_.clear();
    }
  }

  // Fills `out` with the interaction lists of every particle (see the header
  // comment) and calls on_row(i, neighbours, r2, count) right after particle i's
  // row is complete (the thesis computes density and pressure there, Algorithm
  // 4). on_row runs in parallel and may only write particle i's data. If
  // `counters` is given, it receives the totals of the search.
  template <class OnRow>
  void find_neighbours(const ParticleSet<Real>& p, DuplicateCheck check, std::size_t block_size,
                      NeighbourList<Real>& out, OnRow&& on_row, SearchCounters* counters = nullptr) {
    const std::size_t n = p.size();
    if (cells_.size() != n) throw std::logic_error("spatial hash: find_neighbours() on particles it was not built for");
    const std::size_t blocks = parallel::block_count(n, block_size);
    if (block_lists_.size() < blocks) block_lists_.resize(blocks);
    std::vector<SearchCounters> block_counters(counters ? blocks : 0);
    const Real h2 = h_ * h_;
    const std::uint32_t buckets = bucket_count();
    const auto& order = sort_.order();
    const auto& offsets = sort_.offsets();
    const bool precomputed = neighbour_hashes_mode_ == NeighbourHashes::Precomputed;

    parallel::for_blocks("neighbour_search", n, block_size, [&](std::size_t first, std::size_t last, std::size_t blk) {
      BlockList& list = block_lists_[blk];
      list.neighbour.clear();
      list.r2.clear();
      list.row_end.clear();
      SearchCounters local;
      for (std::size_t row = first; row < last; ++row) {
        const std::uint32_t i = order[row];
        const Real xi = sorted_position_[0][row], yi = sorted_position_[1][row], zi = sorted_position_[2][row];
        const Cell ci = sorted_cells_[row];
        const std::size_t row_begin = list.neighbour.size();
        // The thesis's precomputed hashes of the 26 cells around ci, in scan order.
        const std::uint32_t* around = precomputed ? neighbour_hashes_.data() + std::size_t(i) * kAround : nullptr;
        int next_around = 0;
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const Cell c{wrap(ci.i, di), wrap(ci.j, dj), wrap(ci.k, dk)};
              const bool centre = di == 0 && dj == 0 && dk == 0;
              const std::uint32_t b = !precomputed ? hash_cell(c, buckets)
                                      : centre     ? hashes_[i]
                                                   : around[next_around++];
              for (std::uint32_t s = offsets[b]; s < offsets[b + 1]; ++s) {
                if (s == row) continue;  // the particle itself
                if (counters) {
                  ++local.tests;
                  local.redundant_tests += sorted_cells_[s] == c ? 0 : 1;
                }
                if (check == DuplicateCheck::BeforeDistance && !(sorted_cells_[s] == c)) continue;
                const Real r2 = distance2(xi, yi, zi, sorted_position_[0][s], sorted_position_[1][s],
                                          sorted_position_[2][s]);
                if (within(r2, h2)) {
                  if (check == DuplicateCheck::AfterDistance && !(sorted_cells_[s] == c)) continue;
                  list.neighbour.push_back(order[s]);
                  list.r2.push_back(r2);
                }
              }
            }
        list.row_end.push_back(list.neighbour.size());
        on_row(i, list.neighbour.data() + row_begin, list.r2.data() + row_begin, list.neighbour.size() - row_begin);
      }
      if (counters) {
        local.interactions = list.neighbour.size();
        block_counters[blk] = local;
      }
    });
    gather(n, blocks, block_size, out);
    if (counters) {
      *counters = {};
      for (const auto& c : block_counters) *counters += c;
    }
  }

  Real cell_size() const { return h_; }
  std::uint32_t bucket_count() const { return static_cast<std::uint32_t>(sort_.offsets().size() - 1); }
  // offsets()[b] .. offsets()[b+1]: the slots of bucket b in order().
  const std::vector<std::uint32_t>& offsets() const { return sort_.offsets(); }
  // Particle index in each slot, bucket by bucket, by index within a bucket.
  const std::vector<std::uint32_t>& order() const { return sort_.order(); }
  const std::vector<Cell>& cells() const { return cells_; }        // per particle
  const std::vector<std::uint32_t>& hashes() const { return hashes_; }  // per particle
  // The 26 neighbour-cell hashes of particle i at [26·i, 26·i + 26), in the
  // search's scan order (dk, dj, di from −1 to 1, x fastest, the centre left
  // out); empty unless the last build() was NeighbourHashes::Precomputed.
  const std::vector<std::uint32_t>& neighbour_hashes() const { return neighbour_hashes_; }
  static constexpr std::size_t kAround = 26;  // neighbour cells per particle

 private:
  struct BlockList {
    std::vector<std::uint32_t> neighbour;
    std::vector<Real> r2;
    std::vector<std::size_t> row_end;  // end of each row in neighbour, block-local
  };

  // Neighbour cell coordinate with the wrap-around the hash uses anyway
  // (cells at the int32 limits are clamped, see cell_coordinate()).
  static std::int32_t wrap(std::int32_t c, int d) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(c) + static_cast<std::uint32_t>(d));
  }

  // The thesis's neighbour hashing pass: per particle, its cell (read) and the
  // hashes of the 26 cells around it (written), in find_neighbours()' order.
  void precompute_neighbour_hashes(std::uint32_t buckets, std::size_t block_size) {
    const std::size_t n = cells_.size();
    neighbour_hashes_.resize(n * kAround);
    parallel::for_blocks("neighbour_hashes", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        const Cell ci = cells_[i];
        std::uint32_t* out = neighbour_hashes_.data() + i * kAround;
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di)
              if (di != 0 || dj != 0 || dk != 0)
                *out++ = hash_cell(Cell{wrap(ci.i, di), wrap(ci.j, dj), wrap(ci.k, dk)}, buckets);
      }
    });
  }

  // Concatenates the block lists into one CSR list, in block order.
  void gather(std::size_t n, std::size_t blocks, std::size_t block_size, NeighbourList<Real>& out) {
    std::vector<std::size_t> block_start(blocks + 1, 0);
    for (std::size_t b = 0; b < blocks; ++b) block_start[b + 1] = block_start[b] + block_lists_[b].neighbour.size();
    out.row_particle.assign(sort_.order().begin(), sort_.order().end());
    out.offsets.resize(n + 1);
    out.neighbour.resize(block_start[blocks]);
    out.r2.resize(block_start[blocks]);
    out.offsets[0] = 0;
    parallel::for_blocks("gather_lists", n, block_size, [&](std::size_t first, std::size_t last, std::size_t b) {
      const BlockList& list = block_lists_[b];
      std::copy(list.neighbour.begin(), list.neighbour.end(), out.neighbour.begin() + static_cast<std::ptrdiff_t>(block_start[b]));
      std::copy(list.r2.begin(), list.r2.end(), out.r2.begin() + static_cast<std::ptrdiff_t>(block_start[b]));
      for (std::size_t row = first; row < last; ++row) out.offsets[row + 1] = block_start[b] + list.row_end[row - first];
    });
  }

  Real h_ = Real(1);
  std::vector<Cell> cells_;
  std::vector<std::uint32_t> hashes_;
  parallel::CountingSort sort_;
  std::array<std::vector<Real>, 3> sorted_position_;  // positions in slot order, as the thesis's table holds them
  std::vector<Cell> sorted_cells_;                     // cells in slot order, for the cell-relation check
  NeighbourHashes neighbour_hashes_mode_ = NeighbourHashes::OnTheFly;  // of the last build()
  std::vector<std::uint32_t> neighbour_hashes_;        // kAround per particle (Precomputed only)
  std::vector<BlockList> block_lists_;  // kept between searches to avoid reallocation
};

// Compiled once, in src/spatial/spatial_hash.cpp: users link the float and double copies
// instead of compiling them again.
extern template class SpatialHash<float>;
extern template class SpatialHash<double>;

}  // namespace swirl::spatial
