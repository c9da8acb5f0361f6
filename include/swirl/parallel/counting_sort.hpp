// Stable counting sort of small integer keys, in parallel: the thesis's hash
// table build (count, prefix sum into the offset table, scatter; section 4.2.2),
// which the thesis ran serially on the PPE.
//
// The items are cut into contiguous chunks (pinned blocks of the pool); each
// chunk's keys are counted, the per-(key, chunk) counts are prefix-summed in
// key-major order, and each chunk is scattered in index order. The result is THE stable order (ties by index), so it is
// identical for any thread count.
#pragma once

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::parallel {

class CountingSort {
 public:
  // Sorts indices 0..keys.size()-1 by keys[i] ∈ [0, key_count) (precondition,
  // checked by assert only: it is on the hot path). Afterwards
  // offsets()[k] .. offsets()[k+1] is the range of order() holding the indices
  // with key k, in increasing index order.
  // one_thread: the whole sort on the calling thread (the thesis's serial
  // table build); the result is the same.
  void sort(std::span<const std::uint32_t> keys, std::uint32_t key_count, bool one_thread = false) {
    const std::size_t n = keys.size();
    if (key_count == 0) throw std::invalid_argument("counting sort: key_count must be at least 1");
    if (n > 0xffffffffu) throw std::invalid_argument("counting sort: more than 2^32 - 1 items");
    const std::size_t m = key_count;
    // One chunk per thread (each costs key_count counters to clear and sum);
    // a descheduled thread's chunk is taken by another, and the count changes
    // the speed, never the result.
    const std::size_t chunks =
        one_thread ? 1 : std::min<std::size_t>(n / 4096 + 1, static_cast<std::size_t>(thread_count()));
    auto chunk_begin = [&](std::size_t c) { return n * c / chunks; };
    // Keys are cut into as many contiguous ranges for the prefix sum.
    auto key_begin = [&](std::size_t c) { return m * c / chunks; };
    offsets_.assign(m + 1, 0);
    order_.resize(n);
    counts_.assign(chunks * m, 0);
    range_total_.assign(chunks + 1, 0);

    for_blocks_pinned("counting_sort_count", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
      std::uint32_t* count = counts_.data() + c * m;
      for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i) {
        assert(keys[i] < key_count);
        ++count[keys[i]];
      }
    });
    for_blocks_pinned("counting_sort_range_totals", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
      std::uint32_t sum = 0;
      for (std::size_t k = key_begin(c); k < key_begin(c + 1); ++k)
        for (std::size_t t = 0; t < chunks; ++t) sum += counts_[t * m + k];
      range_total_[c + 1] = sum;
    });
    for (std::size_t t = 0; t < chunks; ++t) range_total_[t + 1] += range_total_[t];
    for_blocks_pinned("counting_sort_offsets", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
      std::uint32_t running = range_total_[c];
      for (std::size_t k = key_begin(c); k < key_begin(c + 1); ++k) {
        offsets_[k] = running;
        for (std::size_t t = 0; t < chunks; ++t) {
          std::uint32_t& slot = counts_[t * m + k];
          const std::uint32_t here = slot;
          slot = running;  // becomes chunk t's next write position for key k
          running += here;
        }
      }
    });
    for_blocks_pinned("counting_sort_scatter", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
      std::uint32_t* count = counts_.data() + c * m;
      for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
        order_[count[keys[i]]++] = static_cast<std::uint32_t>(i);
    });
    offsets_[m] = static_cast<std::uint32_t>(n);
  }

  const std::vector<std::uint32_t>& offsets() const { return offsets_; }
  const std::vector<std::uint32_t>& order() const { return order_; }

 private:
  std::vector<std::uint32_t> counts_;   // per (chunk, key), reused between sorts
  std::vector<std::uint32_t> offsets_;  // key_count + 1
  std::vector<std::uint32_t> order_;    // n
  std::vector<std::uint32_t> range_total_;  // chunk + 1: items with keys below each key range
};

}  // namespace swirl::parallel
