// The three parallel schemes of the paper (section 4): exact at λ = 0, every
// mass counted once, deterministic for any thread count.
#include <gtest/gtest.h>

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

using testing::kSchemes;

template <class Real>
class SchemesTest : public ::testing::Test {};
TYPED_TEST_SUITE(SchemesTest, testing::Precisions);

// Small sizes cut 1000 particles into many sub-domains and units, so every
// code path (sub-domain packing, straddling nodes, several chunks) is used.
GravitySettings settings(Scheme scheme, double lambda, double eps, bool small) {
  GravitySettings s;
  s.scheme = scheme;
  s.tree = Tree::Paper;  // the paper's schemes and tree; the linear tree: linear_tree_test.cpp
  s.opening = lambda;
  s.softening = eps;
  if (small) {
    s.subdomain_size = 37;
    s.subtree_nodes = 23;
  }
  return s;
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
  std::vector<double> s(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      double r2 = eps * eps;
      for (int a = 0; a < 3; ++a) r2 += std::pow(double(p.position[a][j]) - double(p.position[a][i]), 2);
      s[i] += double(p.mass[j]) * std::sqrt(r2 - eps * eps) / (r2 * std::sqrt(r2));
    }
  for (Scheme scheme : kSchemes) {
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(to_string(scheme)) + (small ? " small" : " default"));
      const GravityField<Real> tree = testing::tree_field(p, settings(scheme, 0.0, eps, small));
      std::size_t bad = 0;
      for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a)
          bad += std::abs(double(tree.acceleration[a][i]) - double(direct.acceleration[a][i])) > tol * s[i];
        bad += std::abs(double(tree.potential[i]) - double(direct.potential[i])) > tol * std::abs(double(direct.potential[i]));
      }
      EXPECT_EQ(bad, 0u);
    }
  }
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
  for (Scheme scheme : kSchemes) {
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(to_string(scheme)) + (small ? " small" : " default"));
      const GravityField<Real> f = testing::tree_field(p, settings(scheme, 1.0, 0.0, small));
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
  for (Scheme scheme : kSchemes) {
    SCOPED_TRACE(to_string(scheme));
    BarnesHut<Real> tree(settings(scheme, 0.5, 0.01, false));
    GravityField<Real> f;
    tree.compute(p, f, 64);
    const GravityStats& st = tree.stats();
    const auto work = tree.work();
    ASSERT_EQ(work.size(), st.trees);
    EXPECT_DOUBLE_EQ(double(std::accumulate(work.begin(), work.end(), std::uint64_t(0))), st.mean_nodes_visited * n);
    if (scheme == Scheme::Subdomain) {
      EXPECT_GE(st.trees, (n + 207) / 208);  // runs of ≤ 208 particles
    } else if (scheme == Scheme::Subtree) {
      EXPECT_GE(st.trees, (st.nodes + 369) / 370);  // units of ≤ 370 nodes
    } else {
      EXPECT_EQ(st.trees, 1u);
    }
  }
}

TYPED_TEST(SchemesTest, NoParticleOrOneParticleFeelsNothing) {
  using Real = TypeParam;
  for (Scheme scheme : kSchemes) {
    SCOPED_TRACE(to_string(scheme));
    EXPECT_EQ(testing::tree_field(ParticleSet<Real>(), settings(scheme, 0.5, 0.01, false)).size(), 0u);
    ParticleSet<Real> one(1);
    one.position.set(0, {Real(1), Real(2), Real(3)});
    one.mass[0] = 1;
    const auto f = testing::tree_field(one, settings(scheme, 0.5, 0.0, false));
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
  for (Scheme scheme : {Scheme::Subdomain, Scheme::Subtree}) {
    SCOPED_TRACE(to_string(scheme));
    BarnesHut<Real> whole(settings(scheme, 0.5, 0.01, true)), batched(settings(scheme, 0.5, 0.01, true));
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
ParticleSet<Real> run_steps(Scheme scheme, bool small, int threads) {
  parallel::set_thread_count(threads);
  SimulationSettings ss;
  ss.dt = 1.0 / 128;
  ss.block_size = 256;
  Simulation<Real> sim(plummer<Real>(3000, 21), ss);
  sim.add_solver(std::make_unique<GravityForce<Real>>(settings(scheme, 0.5, 0.01, small)));
  sim.start();
  // Several evaluations, so that the sub-domain load balance uses the work
  // counted in the previous one (section 4.1.1).
  for (int s = 0; s < 3; ++s) sim.step();
  return sim.particles();
}

TYPED_TEST(SchemesTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  const int saved = parallel::thread_count();
  for (Scheme scheme : kSchemes) {
    for (bool small : {false, true}) {
      SCOPED_TRACE(std::string(to_string(scheme)) + (small ? " small" : " default"));
      const ParticleSet<Real> one = run_steps<Real>(scheme, small, 1);
      EXPECT_TRUE(testing::same_bits(one, run_steps<Real>(scheme, small, 2)));
      EXPECT_TRUE(testing::same_bits(one, run_steps<Real>(scheme, small, 3)));
    }
  }
  parallel::set_thread_count(saved);
}

}  // namespace
}  // namespace swirl::gravity
