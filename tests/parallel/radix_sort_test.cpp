// The radix sort against std::stable_sort, for both key widths, skipped
// digits, ties, empty input and any thread count.
#include "swirl/parallel/radix_sort.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "swirl/core/random.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::parallel {
namespace {

template <class Key>
std::vector<std::uint32_t> reference_order(const std::vector<Key>& keys, Key mask) {
  std::vector<std::uint32_t> order(keys.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) { return (keys[a] & mask) < (keys[b] & mask); });
  return order;
}

template <class Key>
void expect_sorted_like_reference(const std::vector<Key>& keys, unsigned bits) {
  const Key mask = bits == 8 * sizeof(Key) ? ~Key{0} : static_cast<Key>((Key{1} << bits) - 1);
  RadixSort<Key> sort;
  sort.sort(keys, bits);
  const auto expected = reference_order(keys, mask);
  ASSERT_EQ(sort.order().size(), keys.size());
  for (std::size_t j = 0; j < keys.size(); ++j) {
    ASSERT_EQ(sort.order()[j], expected[j]) << "position " << j;
    ASSERT_EQ(sort.keys()[j], keys[expected[j]] & mask) << "position " << j;
  }
}

std::vector<std::uint64_t> random_keys(std::size_t n, std::uint64_t modulus, std::uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<std::uint64_t> keys(n);
  for (auto& k : keys) k = rng.next() % modulus;
  return keys;
}

TEST(RadixSort, Matches_stable_sort_on_63_bit_keys) {
  expect_sorted_like_reference(random_keys(100000, std::uint64_t{1} << 63, 1), 63);
}

TEST(RadixSort, Keeps_index_order_among_equal_keys) {
  expect_sorted_like_reference(random_keys(50000, 7, 2), 64);  // many ties, most digits skipped
}

TEST(RadixSort, Looks_only_at_the_low_key_bits) {
  expect_sorted_like_reference(random_keys(30000, ~std::uint64_t{0}, 3), 20);
}

TEST(RadixSort, Sorts_32_bit_keys) {
  const auto wide = random_keys(40000, std::uint64_t{1} << 32, 4);
  expect_sorted_like_reference(std::vector<std::uint32_t>(wide.begin(), wide.end()), 32);
}

TEST(RadixSort, Handles_sorted_constant_and_empty_input) {
  std::vector<std::uint32_t> sorted(20000);
  std::iota(sorted.begin(), sorted.end(), 0u);
  expect_sorted_like_reference(sorted, 32);
  expect_sorted_like_reference(std::vector<std::uint32_t>(9000, 42u), 32);  // every digit skipped
  expect_sorted_like_reference(std::vector<std::uint32_t>{}, 32);
  expect_sorted_like_reference(std::vector<std::uint32_t>{5u}, 3);
}

TEST(RadixSort, Reuses_its_buffers_for_a_smaller_input) {
  RadixSort<std::uint64_t> sort;
  sort.sort(random_keys(50000, 1000, 5), 10);
  const auto keys = random_keys(3000, 1000, 6);
  sort.sort(keys, 10);
  EXPECT_EQ(std::vector<std::uint32_t>(sort.order().begin(), sort.order().end()), reference_order(keys, std::uint64_t{1023}));
}

TEST(RadixSort, Same_order_for_any_thread_count) {
  const auto keys = random_keys(200000, std::uint64_t{1} << 40, 7);
  std::vector<std::vector<std::uint32_t>> orders;
  for (int threads : {1, 2, 3}) {
    set_thread_count(threads);
    RadixSort<std::uint64_t> sort;
    sort.sort(keys, 40);
    orders.emplace_back(sort.order().begin(), sort.order().end());
  }
  set_thread_count(2);
  EXPECT_EQ(orders[0], orders[1]);
  EXPECT_EQ(orders[0], orders[2]);
}

TEST(RadixSort, Rejects_a_bad_key_width) {
  RadixSort<std::uint32_t> sort;
  std::vector<std::uint32_t> keys{1, 2};
  EXPECT_THROW(sort.sort(keys, 0), std::invalid_argument);
  EXPECT_THROW(sort.sort(keys, 33), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::parallel
