// Stable counting sort of small integer keys, in parallel: the thesis's hash
// table build (count, prefix sum into the offset table, scatter; section 4.2.2),
// which the thesis ran serially on the PPE.
//
// Each thread counts the keys of one contiguous chunk, the per-(key, chunk)
// counts are prefix-summed in key-major order, and each thread scatters its
// chunk in index order. The result is THE stable order (ties by index), so it is
// identical for any thread count.
#pragma once

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include <omp.h>

namespace swirl::parallel {

class CountingSort {
 public:
  // Sorts indices 0..keys.size()-1 by keys[i] ∈ [0, key_count) (precondition,
  // checked by assert only: it is on the hot path). Afterwards
  // offsets()[k] .. offsets()[k+1] is the range of order() holding the indices
  // with key k, in increasing index order.
  void sort(std::span<const std::uint32_t> keys, std::uint32_t key_count) {
    const std::size_t n = keys.size();
    if (key_count == 0) throw std::invalid_argument("counting sort: key_count must be at least 1");
    if (n > 0xffffffffu) throw std::invalid_argument("counting sort: more than 2^32 - 1 items");
    const std::size_t m = key_count;
    const int wanted = std::max(1, std::min<int>(omp_get_max_threads(), static_cast<int>(n / 4096) + 1));
    offsets_.assign(m + 1, 0);
    order_.resize(n);
    int chunks = 1;  // one per thread of the team actually granted
    std::vector<std::uint32_t> range_total;
    auto chunk_begin = [&](int c) { return n * static_cast<std::size_t>(c) / static_cast<std::size_t>(chunks); };

#pragma omp parallel num_threads(wanted)
    {
#pragma omp single
      {
        chunks = omp_get_num_threads();
        counts_.assign(static_cast<std::size_t>(chunks) * m, 0);
        range_total.assign(static_cast<std::size_t>(chunks) + 1, 0);
      }
      const int c = omp_get_thread_num();
      std::uint32_t* count = counts_.data() + static_cast<std::size_t>(c) * m;
      for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i) {
        assert(keys[i] < key_count);
        ++count[keys[i]];
      }
#pragma omp barrier
      // Keys are split among threads in contiguous ranges for the prefix sum.
      const std::size_t k0 = m * static_cast<std::size_t>(c) / static_cast<std::size_t>(chunks);
      const std::size_t k1 = m * static_cast<std::size_t>(c + 1) / static_cast<std::size_t>(chunks);
      std::uint32_t sum = 0;
      for (std::size_t k = k0; k < k1; ++k)
        for (int t = 0; t < chunks; ++t) sum += counts_[static_cast<std::size_t>(t) * m + k];
      range_total[static_cast<std::size_t>(c) + 1] = sum;
#pragma omp barrier
#pragma omp single
      for (int t = 0; t < chunks; ++t) range_total[static_cast<std::size_t>(t) + 1] += range_total[static_cast<std::size_t>(t)];
      // (implicit barrier after single)
      std::uint32_t running = range_total[static_cast<std::size_t>(c)];
      for (std::size_t k = k0; k < k1; ++k) {
        offsets_[k] = running;
        for (int t = 0; t < chunks; ++t) {
          std::uint32_t& slot = counts_[static_cast<std::size_t>(t) * m + k];
          const std::uint32_t here = slot;
          slot = running;  // becomes chunk t's next write position for key k
          running += here;
        }
      }
#pragma omp barrier
      for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
        order_[count[keys[i]]++] = static_cast<std::uint32_t>(i);
    }
    offsets_[m] = static_cast<std::uint32_t>(n);
  }

  const std::vector<std::uint32_t>& offsets() const { return offsets_; }
  const std::vector<std::uint32_t>& order() const { return order_; }

 private:
  std::vector<std::uint32_t> counts_;   // per (chunk, key), reused between sorts
  std::vector<std::uint32_t> offsets_;  // key_count + 1
  std::vector<std::uint32_t> order_;    // n
};

}  // namespace swirl::parallel
