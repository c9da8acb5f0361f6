// The paper's octree (Fig. 1): what insertion and depth-first numbering guarantee.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/gravity/octree.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class OctreeTest : public ::testing::Test {};
TYPED_TEST_SUITE(OctreeTest, testing::Precisions);

template <class Real>
void check_invariants(const Octree<Real>& tree, const ParticleSet<Real>& p, std::span<const std::uint32_t> members) {
  const auto nodes = tree.nodes();
  ASSERT_FALSE(nodes.empty());
  ASSERT_EQ(nodes[0].end, nodes.size());
  // Every member sits in exactly one leaf, and leaf_of() finds it.
  std::vector<int> seen(p.size(), 0);
  for (std::size_t k = 0; k < tree.leaf_particles().size(); ++k) ++seen[tree.leaf_particles()[k]];
  for (std::uint32_t j : members) EXPECT_EQ(seen[j], 1);
  EXPECT_EQ(tree.leaf_particles().size(), members.size());
  for (std::size_t s = 0; s < members.size(); ++s) {
    const auto& leaf = nodes[tree.leaf_of(s)];
    ASSERT_GT(leaf.count, 0u);
    bool found = false;
    for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) found |= tree.leaf_particles()[k] == members[s];
    EXPECT_TRUE(found);
  }
  // Depth-first numbering: children tile (n, end(n)); a node's mass and
  // moment are its children's; a one-particle leaf is exactly its particle.
  for (std::uint32_t n = 0; n < nodes.size(); ++n) {
    const auto& node = nodes[n];
    if (node.count == 0) {
      ASSERT_LT(n + 1, node.end);
      double m = 0, mx = 0;
      std::uint32_t c = n + 1;
      for (; c < node.end; c = nodes[c].end) {
        ASSERT_LE(nodes[c].end, node.end);
        EXPECT_LT(nodes[c].size, node.size);
        m += nodes[c].mass;
        mx += double(nodes[c].mass) * double(nodes[c].x);
      }
      EXPECT_EQ(c, node.end);
      EXPECT_NEAR(node.mass, m, 1e-5 * m);
      EXPECT_NEAR(node.x, mx / m, 1e-5 * node.size);
    } else {
      EXPECT_EQ(node.end, n + 1);
      if (node.count == 1) {
        const std::uint32_t j = tree.leaf_particles()[node.first];
        EXPECT_EQ(node.x, p.position.x[j]);
        EXPECT_EQ(node.z, p.position.z[j]);
        EXPECT_EQ(node.mass, p.mass[j]);
      }
    }
  }
}

TYPED_TEST(OctreeTest, InsertionBuildsAConsistentDepthFirstTree) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(3000, 31);
  std::vector<std::uint32_t> members(p.size());
  std::iota(members.begin(), members.end(), 0u);
  Octree<Real> tree;
  tree.build(p, members);
  check_invariants(tree, p, members);
  EXPECT_NEAR(tree.nodes()[0].mass, 1.0, 1e-5);
  // A subset (every third particle, in reverse order) builds the same way.
  std::vector<std::uint32_t> subset;
  for (std::uint32_t j = std::uint32_t(p.size()); j-- > 0;)
    if (j % 3 == 0) subset.push_back(j);
  tree.build(p, subset);
  check_invariants(tree, p, subset);
}

TYPED_TEST(OctreeTest, CoincidentParticlesShareABucketAtTheDepthCap) {
  using Real = TypeParam;
  // 300 particles: 100 at one point, 100 at another 10⁻¹² apart (closer than
  // the deepest cell), the rest spread: insertion must terminate.
  ParticleSet<Real> p = uniform_cube<Real>(300, 2);
  for (std::size_t i = 0; i < 100; ++i) p.position.set(i, {Real(0.1), Real(0.2), Real(0.3)});
  for (std::size_t i = 100; i < 200; ++i) p.position.set(i, {Real(-0.2), Real(0.1), Real(0.0)});
  for (std::size_t i = 150; i < 200; ++i) p.position.x[i] += Real(1e-12);
  std::vector<std::uint32_t> members(p.size());
  std::iota(members.begin(), members.end(), 0u);
  Octree<Real> tree;
  tree.build(p, members);
  check_invariants(tree, p, members);
  EXPECT_LE(tree.depth(), Octree<Real>::max_depth);
  std::uint32_t largest = 0;
  for (const auto& node : tree.nodes()) largest = std::max(largest, node.count);
  EXPECT_GE(largest, 100u);

  // The walk skips only the particle itself in its bucket: λ = 0 still gives the direct sum.
  GravitySettings s;
  s.opening = 0;
  s.softening = 0.05;
  GravityField<Real> direct;
  direct_sum(p, Real(s.softening), 64, direct);
  for (Scheme scheme : testing::kSchemes) {
    s.scheme = scheme;
    const auto tree_f = testing::tree_field(p, s);
    for (std::size_t i = 0; i < p.size(); ++i)
      EXPECT_NEAR(tree_f.potential[i], direct.potential[i], 1e-4 * std::abs(direct.potential[i])) << to_string(scheme);
  }
}

TYPED_TEST(OctreeTest, AllParticlesAtOnePointStillBuild) {
  using Real = TypeParam;
  ParticleSet<Real> p(50);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.position.set(i, {Real(1), Real(1), Real(1)});
    p.mass[i] = Real(0.02);
  }
  std::vector<std::uint32_t> members(p.size());
  std::iota(members.begin(), members.end(), 0u);
  Octree<Real> tree;
  tree.build(p, members);
  // The second particle splits the root down to the depth cap (a chain of
  // one-child nodes), where one bucket then takes all 50.
  ASSERT_EQ(tree.nodes().size(), std::size_t(Octree<Real>::max_depth) + 1);
  EXPECT_EQ(tree.depth(), Octree<Real>::max_depth);
  EXPECT_EQ(tree.nodes().back().count, 50u);
  check_invariants(tree, p, members);
}

}  // namespace
}  // namespace swirl::gravity
