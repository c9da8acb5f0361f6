#include "swirl/core/particle_set.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace {

template <class Real>
class ParticleSetTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ParticleSetTest, Precisions);

// A value unique to (field, component, particle), exact in float.
template <class Real>
Real tag(int field, int component, std::size_t i) {
  return Real(field * 10000 + component * 1000) + Real(i);
}

// An integer unique to (integer field, particle), negative for odd fields.
std::int32_t int_tag(int field, std::size_t i) {
  const auto v = static_cast<std::int32_t>(field * 100000 + static_cast<int>(i));
  return field % 2 ? -v : v;
}

template <class Real>
void fill_distinct(swirl::ParticleSet<Real>& p) {
  int f = 0;
  for (auto& view : p.fields()) {
    for (int c = 0; c < view.components; ++c)
      for (std::size_t i = 0; i < p.size(); ++i) view.data[c][i] = tag<Real>(f, c, i);
    ++f;
  }
  int k = 0;
  for (auto& view : p.int_fields()) {
    for (std::size_t i = 0; i < p.size(); ++i) view.data[0][i] = int_tag(k, i);
    ++k;
  }
  for (std::size_t i = 0; i < p.size(); ++i) p.id[i] = 1000 + i;
}

TYPED_TEST(ParticleSetTest, EveryFieldIs64ByteAligned) {
  swirl::ParticleSet<TypeParam> p(37);
  p.add_field("temperature", 1);
  p.add_int_field("kind");
  for (const auto& view : p.fields())
    for (int c = 0; c < view.components; ++c)
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(view.data[c]) % 64, 0u) << view.name;
  for (const auto& view : p.int_fields()) EXPECT_EQ(reinterpret_cast<std::uintptr_t>(view.data[0]) % 64, 0u) << view.name;
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p.id.data()) % 64, 0u);
}

TYPED_TEST(ParticleSetTest, FieldsAreNamedInAFixedOrder) {
  swirl::ParticleSet<TypeParam> p(3);
  p.add_field("vorticity", 3);
  std::vector<std::string> names;
  for (const auto& view : p.fields()) names.emplace_back(view.name);
  const std::vector<std::string> expected{"position", "velocity", "acceleration", "acceleration_prev",
                                          "mass",     "density",  "pressure",     "vorticity"};
  EXPECT_EQ(names, expected);
  EXPECT_EQ(p.fields().back().components, 3);
}

TYPED_TEST(ParticleSetTest, ReorderPermutesEveryFieldAndKeepsIds) {
  using Real = TypeParam;
  constexpr std::size_t n = 101;
  swirl::ParticleSet<Real> p(n);
  p.add_field("scalar_extra", 1);
  p.add_field("vector_extra", 3);
  p.add_int_field("kind");
  p.add_int_field("flag", swirl::FieldUse::Internal);
  fill_distinct(p);

  std::vector<std::size_t> perm(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = (i * 37 + 11) % n;  // 37 is coprime to 101
  p.reorder(perm);

  int f = 0;
  for (const auto& view : p.fields()) {
    for (int c = 0; c < view.components; ++c)
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(view.data[c][i], tag<Real>(f, c, perm[i])) << view.name;
    ++f;
  }
  int k = 0;
  for (const auto& view : p.int_fields()) {
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(view.data[0][i], int_tag(k, perm[i])) << view.name;
    ++k;
  }
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(p.id[i], 1000 + perm[i]);

  // The inverse permutation restores the original order exactly.
  std::vector<std::size_t> inverse(n);
  for (std::size_t i = 0; i < n; ++i) inverse[perm[i]] = i;
  p.reorder(inverse);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(p.id[i], 1000 + i);
  EXPECT_EQ(p.mass[5], tag<Real>(4, 0, 5));
  EXPECT_EQ(p.int_field(1)[5], int_tag(1, 5));
}

TYPED_TEST(ParticleSetTest, ReorderRefusesWhatIsNotAPermutation) {
  swirl::ParticleSet<TypeParam> p(4);
  const std::vector<std::size_t> short_perm{0, 1, 2};
  const std::vector<std::size_t> repeated{0, 1, 1, 3};
  const std::vector<std::size_t> out_of_range{0, 1, 2, 4};
  EXPECT_THROW(p.reorder(short_perm), std::invalid_argument);
  EXPECT_THROW(p.reorder(repeated), std::invalid_argument);
  EXPECT_THROW(p.reorder(out_of_range), std::invalid_argument);
}

TYPED_TEST(ParticleSetTest, ResizeKeepsEveryFieldTheSameLength) {
  swirl::ParticleSet<TypeParam> p(5);
  const auto k = p.add_field("extra", 3);
  const auto kind = p.add_int_field("kind");
  p.int_field(kind)[4] = -3;
  p.resize(9);
  for (const auto& view : p.fields()) EXPECT_NE(view.data[0], nullptr) << view.name;
  EXPECT_EQ(p.extra(k, 2).size(), 9u);
  ASSERT_EQ(p.int_field(kind).size(), 9u);
  EXPECT_EQ(p.int_field(kind)[4], -3);  // kept
  EXPECT_EQ(p.int_field(kind)[8], 0);   // new entries are zero
  EXPECT_EQ(p.position.z.size(), 9u);
  EXPECT_EQ(p.id.size(), 9u);
}

TYPED_TEST(ParticleSetTest, AddFieldIsIdempotentAndGuardsNames) {
  swirl::ParticleSet<TypeParam> p(2);
  const auto a = p.add_field("extra", 1);
  EXPECT_EQ(p.add_field("extra", 1), a);
  EXPECT_THROW(p.add_field("extra", 3), std::invalid_argument);
  EXPECT_THROW(p.add_field("density", 1), std::invalid_argument);
  EXPECT_THROW(p.add_field("two", 2), std::invalid_argument);
}

// Integer fields: one component, zero-filled, found by name; names are one
// namespace with the built-in and real fields.
TYPED_TEST(ParticleSetTest, IntegerFieldsAreNamedAndGuarded) {
  swirl::ParticleSet<TypeParam> p(4);
  const auto real = p.add_field("temperature", 1);
  EXPECT_EQ(p.find_int_field("kind"), p.npos);
  const auto kind = p.add_int_field("kind");
  const auto flag = p.add_int_field("flag", swirl::FieldUse::Internal);
  EXPECT_EQ(p.int_field_count(), 2u);
  EXPECT_EQ(p.find_int_field("kind"), kind);
  EXPECT_EQ(p.find_int_field("flag"), flag);
  EXPECT_EQ(p.find_field("kind"), p.npos);  // not a real field
  EXPECT_EQ(p.find_int_field("temperature"), p.npos);
  EXPECT_EQ(p.add_int_field("kind", swirl::FieldUse::Internal), kind);  // idempotent, keeps its use
  for (std::int32_t v : p.int_field(kind)) EXPECT_EQ(v, 0);

  EXPECT_THROW(p.add_int_field("density"), std::invalid_argument);
  EXPECT_THROW(p.add_int_field("id"), std::invalid_argument);
  EXPECT_THROW(p.add_int_field("temperature"), std::invalid_argument);
  EXPECT_THROW(p.add_field("kind", 1), std::invalid_argument);
  EXPECT_EQ(p.extra_count(), real + 1);

  const auto views = p.int_fields();
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[0].name, "kind");
  EXPECT_EQ(views[0].components, 1);
  EXPECT_FALSE(views[0].internal);
  EXPECT_EQ(views[1].name, "flag");
  EXPECT_TRUE(views[1].internal);
  // Real fields stay real: fields() lists none of the integer ones.
  for (const auto& view : p.fields()) EXPECT_TRUE(view.name != "kind" && view.name != "flag") << view.name;
}

}  // namespace
