// Parallel LSD radix sort of (key, index) pairs: the one sort behind the
// sorted SPH cell grid and the linear gravity octree (the thesis's "future
// work", chapter 6.2: radix sort and reordering along a space-filling curve).
//
// sort(keys, key_bits) orders the indices 0..n-1 by keys[i], ties by index
// (stable). Only the low `key_bits` bits of each key are looked at, in digits of
// kDigitBits bits, least significant first; a digit on which every key agrees
// costs one counting read and no scatter. Each pass is a parallel stable
// counting sort (per-chunk histograms, prefix sum in digit-major order, each
// chunk scatters its own items in order; the chunks run as pinned blocks of the
// pool, so no pass waits at a barrier for a descheduled thread), so the result is THE stable order:
// identical for any thread count and any chunking.
//
// Afterwards order()[j] is the index of the j-th smallest key and keys()[j] its
// key. Buffers are kept between calls: sorting every step allocates nothing once
// the sizes have settled.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::parallel {

template <class Key>
class RadixSort {
  static_assert(std::is_unsigned_v<Key>, "radix sort keys are unsigned integers");

 public:
  static constexpr unsigned kDigitBits = 8;
  static constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;

  // Sorts by the low key_bits bits of keys (1 ≤ key_bits ≤ bits of Key).
  void sort(std::span<const Key> keys, unsigned key_bits) {
    const std::size_t n = keys.size();
    if (key_bits == 0 || key_bits > 8 * sizeof(Key))
      throw std::invalid_argument("radix sort: key_bits must be between 1 and the key's width");
    if (n > 0xffffffffu) throw std::invalid_argument("radix sort: more than 2^32 - 1 items");
    keys_.resize(n);
    order_.resize(n);
    spare_keys_.resize(n);
    spare_order_.resize(n);
    const Key mask = key_bits == 8 * sizeof(Key) ? ~Key{0} : static_cast<Key>((Key{1} << key_bits) - 1);
    // Chunks of at least 8192 items, a few per thread so that a thread that
    // is descheduled leaves chunks for the others to take; the count changes
    // the speed, never the (unique, stable) result.
    const std::size_t chunks =
        std::min<std::size_t>(n / 8192 + 1, static_cast<std::size_t>(4 * thread_count()));
    auto chunk_begin = [&](std::size_t c) { return n * c / chunks; };
    counts_.assign(chunks * kBuckets, 0);
    bool first_pass = true;  // reads the caller's keys and the identity order
    for (unsigned shift = 0; shift < key_bits; shift += kDigitBits) {
      const Key* in_keys = first_pass ? keys.data() : keys_.data();
      for_blocks_pinned("radix_sort_count", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
        std::uint32_t* count = counts_.data() + c * kBuckets;
        std::fill(count, count + kBuckets, 0u);
        for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
          ++count[((in_keys[i] & mask) >> shift) & (kBuckets - 1)];
      });
      // Prefix sum in digit-major, chunk-minor order: chunk t's items with
      // digit d follow those of chunks < t with the same digit.
      std::uint32_t running = 0;
      bool skip = false;
      for (std::size_t d = 0; d < kBuckets; ++d) {
        std::uint32_t with_digit = 0;
        for (std::size_t t = 0; t < chunks; ++t) {
          std::uint32_t& slot = counts_[t * kBuckets + d];
          const std::uint32_t here = slot;
          slot = running;
          running += here;
          with_digit += here;
        }
        if (with_digit == n) skip = true;  // every key has digit d: the pass would not move anything
      }
      if (skip) continue;
      Key* out_keys = spare_keys_.data();
      std::uint32_t* out_order = spare_order_.data();
      const std::uint32_t* in_order = order_.data();
      for_blocks_pinned("radix_sort_scatter", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
        std::uint32_t* count = counts_.data() + c * kBuckets;
        for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i) {
          const Key k = in_keys[i] & mask;
          const std::uint32_t to = count[(k >> shift) & (kBuckets - 1)]++;
          out_keys[to] = k;
          out_order[to] = first_pass ? static_cast<std::uint32_t>(i) : in_order[i];
        }
      });
      keys_.swap(spare_keys_);
      order_.swap(spare_order_);
      first_pass = false;
    }
    if (first_pass) {  // every digit was skipped: the input is already in order
      for_blocks_pinned("radix_sort_copy", chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
        for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i) {
          keys_[i] = keys[i] & mask;
          order_[i] = static_cast<std::uint32_t>(i);
        }
      });
    }
  }

  // order()[j]: index (into the keys given to sort()) of the j-th item in key order.
  std::span<const std::uint32_t> order() const { return order_; }
  // keys()[j]: the (masked) key of the j-th item in key order; non-decreasing.
  std::span<const Key> keys() const { return keys_; }

 private:
  AlignedVector<Key> keys_, spare_keys_;
  AlignedVector<std::uint32_t> order_, spare_order_;
  std::vector<std::uint32_t> counts_;  // per (chunk, digit); after the prefix sum, each chunk's next slot
};

}  // namespace swirl::parallel
