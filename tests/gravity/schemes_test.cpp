// The three parallel schemes of the paper (section 4): exact at λ = 0, every
// mass counted once, deterministic for any thread count.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class SchemesTest : public ::testing::Test {};
TYPED_TEST_SUITE(SchemesTest, testing::Precisions);

// Every way to split the work: the three schemes and the paper's variants
// (settings.hpp): the subdomain split, the subtree split and upper nodes.
struct Variant {
  const char* name;
  Scheme scheme;
  SubdomainSplit subdomain_split = SubdomainSplit::Adaptive;
  SubtreeSplit subtree_split = SubtreeSplit::Units;
  UpperNodes upper_nodes = UpperNodes::Opened;
};
constexpr std::array<Variant, 7> kVariants{{
    {"subdomain", Scheme::Subdomain},
    {"subdomain, paper's 512 cells", Scheme::Subdomain, SubdomainSplit::Paper},
    {"subtree", Scheme::Subtree},
    {"subtree, paper's parts", Scheme::Subtree, SubdomainSplit::Adaptive, SubtreeSplit::Parts},
    {"subtree, upper clusters", Scheme::Subtree, SubdomainSplit::Adaptive, SubtreeSplit::Units, UpperNodes::Clusters},
    {"subtree, paper's parts and upper clusters", Scheme::Subtree, SubdomainSplit::Adaptive, SubtreeSplit::Parts,
     UpperNodes::Clusters},
    {"global", Scheme::Global},
}};

// Small sizes cut 1000 particles into many sub-domains and units, so every
// code path (sub-domain packing, straddling nodes, several chunks) is used;
// so do 37 parts of the paper's subtree split.
GravitySettings settings(const Variant& v, double lambda, double eps, bool small) {
  GravitySettings s;
  s.scheme = v.scheme;
  s.subdomain_split = v.subdomain_split;
  s.subtree_split = v.subtree_split;
  s.upper_nodes = v.upper_nodes;
  s.tree = Tree::Paper;  // the paper's schemes and tree; the linear tree: linear_tree_test.cpp
  s.opening = lambda;
  s.softening = eps;
  if (small) {
    s.subdomain_size = 37;
    s.subtree_nodes = 23;
    s.subtree_parts = 37;
  }
  return s;
}
GravitySettings settings(Scheme scheme, double lambda, double eps, bool small) {
  return settings(Variant{"", scheme}, lambda, eps, small);
}

// Σ_j m_j |r_ij| / (r_ij² + ε²)^{3/2}: the size of the terms particle i's
// acceleration sums, which bounds its round-off.
template <class Real>
std::vector<double> term_magnitudes(const ParticleSet<Real>& p, double eps) {
  std::vector<double> s(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (j == i) continue;
      double r2 = eps * eps;
      for (int a = 0; a < 3; ++a) r2 += std::pow(double(p.position[a][j]) - double(p.position[a][i]), 2);
      s[i] += double(p.mass[j]) * std::sqrt(r2 - eps * eps) / (r2 * std::sqrt(r2));
    }
  return s;
}

// Particles whose field differs from ref by more than tol · (terms' size).
template <class Real>
std::size_t beyond_round_off(const GravityField<Real>& f, const GravityField<Real>& ref, const std::vector<double>& s,
                             double tol) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    for (int a = 0; a < 3; ++a)
      bad += std::abs(double(f.acceleration[a][i]) - double(ref.acceleration[a][i])) > tol * s[i];
    bad += std::abs(double(f.potential[i]) - double(ref.potential[i])) > tol * std::abs(double(ref.potential[i]));
  }
  return bad;
}

TYPED_TEST(SchemesTest, LambdaZeroIsTheDirectSumToRoundOff) {
  using Real = TypeParam;
  constexpr std::size_t n = 1000;
  // A Plummer sphere plus a clump of coincident particles (a bucket leaf at the depth cap).
  ParticleSet<Real> p = plummer<Real>(n, 7);
  for (std::size_t i = 0; i < 20; ++i) p.position.set(i, Vec3<Real>{Real(0.25), Real(-0.125), Real(0.5)});
  constexpr double eps = 0.02;
  GravityField<Real> direct;
  direct_sum(p, Real(eps), 64, direct);

  // Round-off: both sides add the same N − 1 terms in different orders; a sum
  // of N terms is off by at most ~u·√N·Σ|term| (random rounding, with margin:
  // u·(4 + 2√N)), Σ|term| being the sum of magnitudes S_i (for φ: |φ_i|).
  const double u = std::numeric_limits<Real>::epsilon() / 2;
  const double tol = u * (4 + 2 * std::sqrt(double(n)));
  const std::vector<double> s = term_magnitudes(p, eps);
  for (const Variant& v : kVariants) {
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(v.name) + (small ? " small" : " default"));
      EXPECT_EQ(beyond_round_off(testing::tree_field(p, settings(v, 0.0, eps, small)), direct, s, tol), 0u);
    }
  }
}

// With the paper's upper nodes as clusters, the units together make exactly
// the global walk's interactions (every accepted upper node counted by one
// unit): the same field but for the order of the sum.
TYPED_TEST(SchemesTest, UpperNodesAsClustersGiveTheGlobalWalksField) {
  using Real = TypeParam;
  constexpr std::size_t n = 1500;
  const ParticleSet<Real> p = plummer<Real>(n, 13);
  constexpr double eps = 0.01;
  const GravityField<Real> global = testing::tree_field(p, settings(Scheme::Global, 0.6, eps, false));
  const double u = std::numeric_limits<Real>::epsilon() / 2;
  // Cluster terms are at most (1 − λ)⁻² times their particles' terms: margin 8.
  const double tol = 8 * u * (4 + 2 * std::sqrt(double(n)));
  const std::vector<double> s = term_magnitudes(p, eps);
  for (const Variant& v : kVariants) {
    if (v.upper_nodes != UpperNodes::Clusters) continue;
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(v.name) + (small ? " small" : " default"));
      BarnesHut<Real> tree(settings(v, 0.6, eps, small));
      GravityField<Real> f;
      tree.compute(p, f, 64);
      ASSERT_GT(tree.stats().trees, 1u);
      EXPECT_EQ(beyond_round_off(f, global, s, tol), 0u);
    }
  }
  // ... while opening the upper nodes (ours) gives a different, finer sum.
  const auto opened = testing::tree_field(p, settings(Scheme::Subtree, 0.6, eps, true));
  EXPECT_GT(beyond_round_off(opened, global, s, tol), n / 10);
}

TYPED_TEST(SchemesTest, LambdaZeroVisitsEveryNodeOfTheGlobalTree) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(500, 3);
  BarnesHut<Real> tree(settings(Scheme::Global, 0.0, 0.01, false));
  GravityField<Real> f;
  tree.compute(p, f, 64);
  EXPECT_EQ(tree.stats().mean_nodes_visited, double(tree.stats().nodes));
  EXPECT_GT(tree.stats().nodes, p.size());
}

TYPED_TEST(SchemesTest, ADistantProbeFeelsEveryMassExactlyOnce) {
  using Real = TypeParam;
  // A cluster of total mass 1 and a massless probe far away: with λ = 1 the
  // probe uses the largest clusters each scheme allows. If a straddling node
  // (subtree) or anything else were counted twice, the pull would be ≥ 2×.
  constexpr std::size_t n = 2000;
  ParticleSet<Real> p = plummer<Real>(n, 11, {0.9});  // the cut keeps the cluster within r ≈ 3
  p.resize(n + 1);
  const double D = 1000;
  p.position.set(n, Vec3<Real>{Real(D), 0, 0});
  p.mass[n] = 0;
  p.id[n] = n;
  for (const Variant& v : kVariants) {
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(v.name) + (small ? " small" : " default"));
      const GravityField<Real> f = testing::tree_field(p, settings(v, 1.0, 0.0, small));
      // Monopole pull −M/D² (M = 1; the cluster's centre of mass is at the
      // origin): the quadrupole correction is ~ (r/D)² ≈ 10⁻⁵ relative.
      EXPECT_NEAR(f.acceleration.x[n] * D * D, -1.0, 1e-4);
      EXPECT_NEAR(f.potential[n] * D, -1.0, 1e-4);
    }
  }
}

TYPED_TEST(SchemesTest, OneUnitHoldingTheWholeTreeIsTheGlobalWalk) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(1500, 5);
  GravitySettings s = settings(Scheme::Subtree, 0.6, 0.01, false);
  s.subtree_nodes = 1u << 30;
  const auto one_unit = testing::tree_field(p, s);
  s.scheme = Scheme::Global;
  EXPECT_TRUE(testing::same_bits(one_unit, testing::tree_field(p, s)));
  // ... and units of the paper's size change the sums (the test can tell).
  s.scheme = Scheme::Subtree;
  s.subtree_nodes = 370;
  EXPECT_FALSE(testing::same_bits(one_unit, testing::tree_field(p, s)));
}

TYPED_TEST(SchemesTest, SubdomainsAndUnitsRespectTheirSizesAndCountTheirWork) {
  using Real = TypeParam;
  constexpr std::size_t n = 4096;
  const ParticleSet<Real> p = plummer<Real>(n, 9);
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(v.name);
    const GravitySettings s = settings(v, 0.5, 0.01, false);
    BarnesHut<Real> tree(s);
    GravityField<Real> f;
    tree.compute(p, f, 64);
    const GravityStats& st = tree.stats();
    const auto work = tree.work();
    ASSERT_EQ(work.size(), st.trees);
    ASSERT_EQ(tree.balance_weights().size(), v.scheme == Scheme::Global ? 0u : st.trees);
    EXPECT_DOUBLE_EQ(double(std::accumulate(work.begin(), work.end(), std::uint64_t(0))), st.mean_nodes_visited * n);
    if (v.scheme == Scheme::Subdomain) {
      ASSERT_EQ(tree.subdomains().size(), st.trees);
      std::size_t next = 0;
      for (const auto& [b, e] : tree.subdomains()) {  // consecutive runs of 1 to 208 particles
        EXPECT_EQ(b, next);
        EXPECT_GE(e - b, 1u);
        EXPECT_LE(e - b, 208u);
        next = e;
      }
      EXPECT_EQ(next, n);
    } else if (v.scheme == Scheme::Subtree) {
      const std::size_t unit = v.subtree_split == SubtreeSplit::Parts ? (st.nodes + 7) / 8 : 370;
      EXPECT_GE(st.trees, (st.nodes + unit - 1) / unit);  // units of ≤ `unit` nodes
      if (v.subtree_split == SubtreeSplit::Parts) {
        EXPECT_LE(st.trees, 16u);  // about 8 parts
      }
      // Units are dealt by their nodes: together, every node below the straddling ones.
      const auto w = tree.balance_weights();
      EXPECT_LE(std::accumulate(w.begin(), w.end(), std::uint64_t(0)), st.nodes);
      EXPECT_GT(std::accumulate(w.begin(), w.end(), std::uint64_t(0)), st.nodes / 2);
    } else {
      EXPECT_EQ(st.trees, 1u);
    }
  }
}

// A 16³ lattice puts exactly 8 particles in each of the paper's 512 cells, so
// its split is known: runs of 26 whole cells (208 particles), in Morton order.
template <class Real>
ParticleSet<Real> lattice16() {
  ParticleSet<Real> p(4096);
  for (std::size_t i = 0; i < 4096; ++i) {
    p.position.set(i, Vec3<Real>{Real((double(i % 16) + 0.5) / 16), Real((double(i / 16 % 16) + 0.5) / 16),
                                 Real((double(i / 256) + 0.5) / 16)});
    p.mass[i] = Real(1.0 / 4096);
    p.id[i] = i;
  }
  return p;
}

TYPED_TEST(SchemesTest, ThePapersSubdomainsAreWholeCellsOfTheFixed512) {
  using Real = TypeParam;
  GravitySettings s = settings(Scheme::Subdomain, 0.5, 0.01, false);
  s.subdomain_split = SubdomainSplit::Paper;
  BarnesHut<Real> paper(s);
  GravityField<Real> f;
  paper.compute(lattice16<Real>(), f, 64);
  ASSERT_EQ(paper.subdomains().size(), 20u);  // ⌈512 / 26⌉
  for (std::size_t t = 0; t < 19; ++t) EXPECT_EQ(paper.subdomains()[t].second - paper.subdomains()[t].first, 208u);
  EXPECT_EQ(paper.subdomains()[19].second - paper.subdomains()[19].first, 18u * 8);
  // Ours splits from the root: 64-particle cells at level 2, three per run.
  s.subdomain_split = SubdomainSplit::Adaptive;
  BarnesHut<Real> adaptive(s);
  adaptive.compute(lattice16<Real>(), f, 64);
  ASSERT_EQ(adaptive.subdomains().size(), 22u);  // ⌈64 / 3⌉
  EXPECT_EQ(adaptive.subdomains()[0].second, 192u);
}

// Section 4.1.1: a sub-domain is weighed by the nodes it explored last time.
// The weight follows the sub-domain (its cells), not its index: new ones are
// estimated from their particles and the last nodes per particle.
TYPED_TEST(SchemesTest, TheBalanceFollowsEachSubdomainItMeasured) {
  using Real = TypeParam;
  GravitySettings s = settings(Scheme::Subdomain, 0.5, 0.01, false);
  s.subdomain_split = SubdomainSplit::Paper;
  BarnesHut<Real> tree(s);
  GravityField<Real> f;
  ParticleSet<Real> p = lattice16<Real>();
  tree.compute(p, f, 64);
  const std::vector<std::uint64_t> counts(tree.balance_weights().begin(), tree.balance_weights().end());
  for (std::size_t t = 0; t < counts.size(); ++t)  // the first evaluation: particles
    EXPECT_EQ(counts[t], tree.subdomains()[t].second - tree.subdomains()[t].first);
  const std::vector<std::uint64_t> measured(tree.work().begin(), tree.work().end());
  const double per_particle = tree.stats().mean_nodes_visited;
  // 100 more particles in the last cell (inside the lattice's cube): the last
  // run of 18 cells becomes runs of 17 cells and of that cell; the first 19 are unchanged.
  const std::size_t n = p.size();
  p.resize(n + 100);
  for (std::size_t k = 0; k < 100; ++k) {
    const double t = double(k) / 100;
    p.position.set(n + k, Vec3<Real>{Real(0.92 + 0.04 * t), Real(0.96 - 0.04 * t), Real(0.93 + 0.02 * t)});
    p.mass[n + k] = Real(1.0 / 4096);
    p.id[n + k] = n + k;
  }
  tree.compute(p, f, 64);
  ASSERT_EQ(tree.subdomains().size(), 21u);
  const auto w = tree.balance_weights();
  for (std::size_t t = 0; t < 19; ++t) EXPECT_EQ(w[t], measured[t]) << t;
  for (std::size_t t = 19; t < 21; ++t) {
    const auto [b, e] = tree.subdomains()[t];
    EXPECT_EQ(w[t], std::uint64_t(std::llround(per_particle * double(e - b)))) << t;
  }
  EXPECT_EQ(tree.subdomains()[20].second - tree.subdomains()[20].first, 108u);
}

TYPED_TEST(SchemesTest, NoParticleOrOneParticleFeelsNothing) {
  using Real = TypeParam;
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(v.name);
    EXPECT_EQ(testing::tree_field(ParticleSet<Real>(), settings(v, 0.5, 0.01, false)).size(), 0u);
    ParticleSet<Real> one(1);
    one.position.set(0, {Real(1), Real(2), Real(3)});
    one.mass[0] = 1;
    const auto f = testing::tree_field(one, settings(v, 0.5, 0.0, false));
    EXPECT_EQ(f.acceleration.get(0), Vec3<Real>{});
    EXPECT_EQ(f.potential[0], Real(0));
  }
}

// The trees are walked and dealt in batches that the buffer budget holds; a
// budget of one tree per thread (many batches) gives the bits of one batch.
TYPED_TEST(SchemesTest, TreesInManySmallBatchesGiveTheSameBitsAsOneBatch) {
  using Real = TypeParam;
  const int saved = parallel::thread_count();
  parallel::set_thread_count(2);
  const auto p = plummer<Real>(3000, 5);
  for (const Variant& v : kVariants) {
    if (v.scheme == Scheme::Global) continue;
    SCOPED_TRACE(v.name);
    BarnesHut<Real> whole(settings(v, 0.5, 0.01, true)), batched(settings(v, 0.5, 0.01, true));
    batched.set_tree_buffer_bytes(1);  // one tree per thread per batch
    GravityField<Real> a, b;
    for (int evaluation = 0; evaluation < 2; ++evaluation) {  // the second deals by measured work
      whole.compute(p, a, 256);
      batched.compute(p, b, 256);
      ASSERT_GT(whole.work().size(), 4u) << "several batches need several trees";
      for (std::size_t i = 0; i < p.size(); ++i) {
        ASSERT_EQ(a.acceleration.get(i), b.acceleration.get(i)) << i;
        ASSERT_EQ(a.potential[i], b.potential[i]) << i;
      }
    }
  }
  parallel::set_thread_count(saved);
}

template <class Real>
ParticleSet<Real> run_steps(const Variant& v, bool small, int threads) {
  parallel::set_thread_count(threads);
  SimulationSettings ss;
  ss.dt = 1.0 / 128;
  ss.block_size = 256;
  Simulation<Real> sim(plummer<Real>(3000, 21), ss);
  sim.add_solver(std::make_unique<GravityForce<Real>>(settings(v, 0.5, 0.01, small)));
  sim.start();
  // Several evaluations, so that the sub-domain load balance uses the work
  // counted in the previous one (section 4.1.1).
  for (int s = 0; s < 3; ++s) sim.step();
  return sim.particles();
}

TYPED_TEST(SchemesTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  const int saved = parallel::thread_count();
  for (const Variant& v : kVariants) {
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(v.name) + (small ? " small" : " default"));
      const ParticleSet<Real> one = run_steps<Real>(v, small, 1);
      EXPECT_TRUE(testing::same_bits(one, run_steps<Real>(v, small, 2)));
      EXPECT_TRUE(testing::same_bits(one, run_steps<Real>(v, small, 3)));
    }
  }
  parallel::set_thread_count(saved);
}

}  // namespace
}  // namespace swirl::gravity
