// OccupiedCellTable: the cell ranges of a SortedCellGrid (spatial/cell_grid.hpp)
// when a dense table over every cell would be too large (particles spread over
// a huge or unbounded region: cells ≫ particles). An open-addressing hash
// table (linear probing, 2^b slots, at least twice the occupied cells) holding,
// for each occupied cell only, its key and its index range in the sorted order.
// Memory: 16 bytes per slot, at most 4 slots per particle.
//
// build(keys): from the sorted keys, in parallel: the first particle of each
// cell claims a slot with a compare-and-swap on the slot's key (threads may
// claim slots in any order, so the slots' layout may differ between runs; what
// range(key) returns does not). range(key): the cell's [begin, end), or an
// empty range for an unoccupied cell.
//
// Invariant: range(k) equals the dense table's [start[k], start[k + 1]) for
// every key k (tested on the same particles).
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "swirl/core/index_range.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::spatial {

class OccupiedCellTable {
 public:
  // keys: sorted ascending, each below 2^63.
  void build(std::span<const std::uint64_t> keys, std::size_t block_size) {
    const std::size_t n = keys.size();
    const std::size_t occupied = parallel::reduce_blocks_pinned(
        "cell_hash_count", n, block_size, std::size_t{0},
        [&](std::size_t b, std::size_t e) {
          std::size_t c = 0;
          for (std::size_t i = b; i < e; ++i) c += i == 0 || keys[i] != keys[i - 1];
          return c;
        },
        [](std::size_t a, std::size_t b) { return a + b; });
    const std::size_t slots = std::bit_ceil(std::max<std::size_t>(16, 2 * occupied));
    shift_ = 64 - static_cast<unsigned>(std::countr_zero(slots));
    mask_ = slots - 1;
    slots_.assign(slots, Slot{});
    parallel::for_blocks_pinned("cell_hash_build", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        if (i > 0 && keys[i] == keys[i - 1]) continue;  // not the first particle of its cell
        std::size_t end = i + 1;
        while (end < n && keys[end] == keys[i]) ++end;
        insert(keys[i], static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(end));
      }
    });
  }

  IndexRange range(std::uint64_t key) const {
    for (std::size_t s = home(key);; s = (s + 1) & mask_) {
      const Slot& slot = slots_[s];
      if (slot.key == key) return {slot.begin, slot.end};
      if (slot.key == kEmpty) return {};
    }
  }

  void clear() { slots_.clear(); }
  std::size_t slots() const { return slots_.size(); }
  std::size_t bytes() const { return slots_.capacity() * sizeof(Slot); }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no key reaches 2^64 − 1
  struct Slot {
    std::uint64_t key = kEmpty;
    std::uint32_t begin = 0, end = 0;
  };

  // Fibonacci hashing: the top bits of key · 2^64/φ.
  std::size_t home(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ULL) >> shift_) & mask_;
  }

  // Each key is inserted once (by its cell's first particle); the payload is
  // written by the thread that claimed the slot and read only after the
  // parallel loop's barrier.
  void insert(std::uint64_t key, std::uint32_t begin, std::uint32_t end) {
    for (std::size_t s = home(key);; s = (s + 1) & mask_) {
      std::atomic_ref<std::uint64_t> slot_key(slots_[s].key);
      std::uint64_t expected = kEmpty;
      if (slot_key.compare_exchange_strong(expected, key, std::memory_order_relaxed)) {
        slots_[s].begin = begin;
        slots_[s].end = end;
        return;
      }
    }
  }

  unsigned shift_ = 60;
  std::size_t mask_ = 15;
  std::vector<Slot> slots_;
};

}  // namespace swirl::spatial
