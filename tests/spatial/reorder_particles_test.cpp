// spatial::ParticleReorder (the order's parallel reorder) against its slow
// twin ParticleSet::reorder: the same bits in every field, real and integer,
// and in the ids, for any thread count and block size — also when the integer
// fields outnumber the real ones' groups, so some loops move integers only.
#include "swirl/spatial/reorder_particles.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "swirl/core/random.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace {

using namespace swirl;

template <class Real>
class ReorderParticlesTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ReorderParticlesTest, Precisions);

// n particles with every field random: `reals` extra scalar real fields and
// `ints` integer fields (every other one internal).
template <class Real>
ParticleSet<Real> random_set(std::size_t n, int reals, int ints, std::uint64_t seed) {
  ParticleSet<Real> p(n);
  for (int k = 0; k < reals; ++k) p.add_field("real" + std::to_string(k), 1);
  for (int k = 0; k < ints; ++k)
    p.add_int_field("int" + std::to_string(k), k % 2 ? FieldUse::Internal : FieldUse::Output);
  SplitMix64 rng(seed);
  for (auto& f : p.fields())
    for (int c = 0; c < f.components; ++c)
      for (std::size_t i = 0; i < n; ++i) f.data[c][i] = Real(rng.uniform() - 0.5);
  for (auto& f : p.int_fields())
    for (std::size_t i = 0; i < n; ++i) f.data[0][i] = static_cast<std::int32_t>(rng.next());
  for (std::size_t i = 0; i < n; ++i) p.id[i] = rng.next();
  return p;
}

// A random permutation (Fisher-Yates on SplitMix64).
std::vector<std::uint32_t> random_order(std::size_t n, std::uint64_t seed) {
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  SplitMix64 rng(seed);
  for (std::size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.next() % i]);
  return order;
}

template <class Real>
void expect_bit_identical(const ParticleSet<Real>& a, const ParticleSet<Real>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(a.id, b.id) << what;
  if (a.size() == 0) return;  // empty arrays may have no storage: nothing to compare, and memcmp wants pointers
  const auto fa = a.fields(), fb = b.fields();
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      EXPECT_EQ(std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(Real)), 0) << what << ": " << fa[f].name;
  const auto ia = a.int_fields(), ib = b.int_fields();
  ASSERT_EQ(ia.size(), ib.size());
  for (std::size_t f = 0; f < ia.size(); ++f)
    EXPECT_EQ(std::memcmp(ia[f].data[0], ib[f].data[0], a.size() * sizeof(std::int32_t)), 0) << what << ": " << ia[f].name;
}

TYPED_TEST(ReorderParticlesTest, MatchesTheSlowTwinForAnyThreadCount) {
  using Real = TypeParam;
  const int before = parallel::thread_count();
  const std::size_t n = 5003;  // not a multiple of any block size below
  // No integer field; fewer integer groups than real ones; more (20 integer
  // fields: 5 groups of four against the built-ins' 4 real groups).
  for (const auto& [reals, ints] : {std::pair{0, 0}, std::pair{2, 6}, std::pair{1, 20}}) {
    const auto original = random_set<Real>(n, reals, ints, 7 + static_cast<std::uint64_t>(ints));
    const auto order = random_order(n, 99);
    auto slow = original;
    slow.reorder(std::vector<std::size_t>(order.begin(), order.end()));
    for (int threads : {1, 2, 3})
      for (std::size_t block : {std::size_t{64}, std::size_t{1000}, n}) {
        parallel::set_thread_count(threads);
        auto fast = original;
        spatial::ParticleReorder<Real> reorder;
        reorder.apply(fast, order, block);
        const std::string what = std::to_string(ints) + " integer fields, " + std::to_string(threads) +
                                 " threads, blocks of " + std::to_string(block);
        expect_bit_identical(fast, slow, what);
        // Scratch: four real fields and the ids, plus integer scratch only when used.
        const std::size_t int_scratch = std::min<std::size_t>(4, static_cast<std::size_t>(ints)) * n * sizeof(std::int32_t);
        EXPECT_GE(reorder.bytes(), 4 * n * sizeof(Real) + n * sizeof(std::uint64_t) + int_scratch) << what;
        if (ints == 0) {
          EXPECT_LT(reorder.bytes(), 4 * n * sizeof(Real) + n * sizeof(std::uint64_t) + 4 * n) << what;
        }
      }
  }
  parallel::set_thread_count(before);
}

// A second reorder reuses the scratch (swapped with the fields) and still
// matches: the inverse order restores the original bits.
TYPED_TEST(ReorderParticlesTest, TheInverseOrderRestoresTheOriginal) {
  using Real = TypeParam;
  const std::size_t n = 777;
  const auto original = random_set<Real>(n, 3, 5, 11);
  const auto order = random_order(n, 12);
  std::vector<std::uint32_t> inverse(n);
  for (std::size_t i = 0; i < n; ++i) inverse[order[i]] = static_cast<std::uint32_t>(i);
  auto p = original;
  spatial::ParticleReorder<Real> reorder;
  reorder.apply(p, order, 100);
  EXPECT_NE(p.id, original.id);
  reorder.apply(p, inverse, 100);
  expect_bit_identical(p, original, "inverse");
}

// select(): a gather to fewer (or as many) particles, against the slow twin
// ParticleSet::subset, with more fields than one group (the scratch, swapped
// out by each group, must take the new size every time), and again after a
// same-size reorder with the same object (scratch of another size).
TYPED_TEST(ReorderParticlesTest, SelectMatchesSubsetAndShrinksEveryField) {
  using Real = TypeParam;
  const std::size_t n = 3001;
  const auto original = random_set<Real>(n, 5, 9, 21);
  spatial::ParticleReorder<Real> reorder;
  for (const std::size_t keep : {std::size_t{2000}, n, std::size_t{1}, std::size_t{0}}) {
    auto picked = random_order(n, 31 + keep);
    picked.resize(keep);
    auto fast = original;
    reorder.apply(fast, random_order(n, 5), 256);  // scratch of the full size first
    auto slow = fast.subset(std::vector<std::size_t>(picked.begin(), picked.end()));
    reorder.select(fast, picked, 256);
    ASSERT_EQ(fast.size(), keep);
    fast.for_each_array([&](const AlignedVector<Real>& a) { EXPECT_EQ(a.size(), keep); });
    fast.for_each_int_array([&](const AlignedVector<std::int32_t>& a) { EXPECT_EQ(a.size(), keep); });
    EXPECT_EQ(fast.id.size(), keep);
    expect_bit_identical(fast, slow, "select " + std::to_string(keep));
  }
}

}  // namespace
