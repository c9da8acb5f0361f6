// The linear octree (linear_octree.hpp) against its slow twins: the direct
// sum and an independent check of every structural invariant.
//
// Accuracy bounds (Plummer sphere, 4096 particles, ε = 0.01, Barnes' rule).
// A monopole's leading error is the quadrupole term: one node of side l seen
// from d ≥ l/θ errs by ≲ (3/8)(l/d)² ≤ (3/8)θ² relative (accuracy_test.cpp);
// with the quadrupole the leading error is the octupole, one more power of
// l/d ≤ θ. Summed over hundreds of nodes in unrelated directions, mostly well
// inside the criterion, the median particle sees about a tenth of one node's
// error. Asserted: monopole median ≤ 0.04·θ², quadrupole median ≤ 0.04·θ³
// and below half the monopole's median, the quadrupole's 99th percentile and
// its potential energy error below the monopole's: strictly more accurate on
// the same particles at the same θ. (Measured, float and double alike:
// θ = 0.5 median 1.37e-3 → 4.1e-4, p99 6.4e-3 → 1.8e-3; θ = 0.7 median
// 3.2e-3 → 1.3e-3, p99 1.8e-2 → 7.4e-3.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/gravity/linear_octree.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {
namespace {

using testing::quantile;

template <class Real>
class LinearTreeTest : public ::testing::Test {};
TYPED_TEST_SUITE(LinearTreeTest, testing::Precisions);

LinearTreeSettings tree_settings(Multipole multipole, Criterion criterion, double opening, double eps,
                                 std::size_t bucket = 16) {
  LinearTreeSettings s;
  s.walk = Walk::Particle;  // these are the per-particle walk's tests; group_walk_test.cpp tests the group walk
  s.multipole = multipole;
  s.criterion = criterion;
  s.opening = opening;
  s.softening = eps;
  s.bucket_size = bucket;
  return s;
}

// A Plummer sphere with a clump of coincident particles (more than any
// bucket: they share one finest-level leaf) and an outlier far away.
template <class Real>
ParticleSet<Real> awkward_set(std::size_t n) {
  ParticleSet<Real> p = plummer<Real>(n, 7);
  const std::size_t clump = 100;
  for (std::size_t i = 0; i < clump; ++i) p.position.set(i, {Real(0.25), Real(-0.5), Real(0.125)});
  p.position.set(clump, {Real(40), Real(-30), Real(10)});
  return p;
}

template <class Real>
void check_invariants(const LinearOctree<Real>& tree, const ParticleSet<Real>& p, std::size_t bucket) {
  const LinearNodes<Real>& t = tree.nodes();
  const std::size_t n = p.size();
  ASSERT_GT(t.size(), 0u);
  // Keys sorted; order a permutation; sorted copies are the particles.
  const auto keys = tree.keys();
  ASSERT_EQ(keys.size(), n);
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  std::vector<int> seen(n, 0);
  for (std::size_t s = 0; s < n; ++s) {
    const std::uint32_t i = tree.order()[s];
    ASSERT_LT(i, n);
    ++seen[i];
    ASSERT_EQ(tree.x()[s], p.position.x[i]);
    ASSERT_EQ(tree.y()[s], p.position.y[i]);
    ASSERT_EQ(tree.z()[s], p.position.z[i]);
    ASSERT_EQ(tree.m()[s], p.mass[i]);
  }
  for (int c : seen) ASSERT_EQ(c, 1);

  // Every particle in exactly one leaf.
  std::vector<int> in_leaf(n, 0);
  const double side = tree.root_side();
  const auto corner = tree.root_corner();
  for (std::size_t node = 0; node < t.size(); ++node) {
    const std::uint32_t b = t.begin[node], e = t.end[node];
    ASSERT_LT(b, e) << "empty node " << node;
    const int level = t.level[node];
    if (t.child_count[node] == 0) {
      for (std::uint32_t s = b; s < e; ++s) ++in_leaf[s];
      // A leaf holds at most a bucket, unless it is at the finest level.
      if (level < LinearOctree<Real>::kLevels) {
        EXPECT_LE(e - b, bucket);
      }
    } else {
      // Children contiguous, one level down, partitioning the parent's range in order.
      std::uint32_t next = b;
      double child_mass = 0;
      for (std::uint32_t c = t.first_child[node]; c < t.first_child[node] + t.child_count[node]; ++c) {
        ASSERT_LT(c, t.size());
        EXPECT_EQ(t.level[c], level + 1);
        EXPECT_EQ(t.begin[c], next);
        EXPECT_EQ(t.prefix[c] >> 3, t.prefix[node]);
        next = t.end[c];
        child_mass += double(t.mass[c]);
      }
      EXPECT_EQ(next, e);
      EXPECT_GT(e - b, bucket);
      // Node mass equals the sum of its children's (up to rounding to Real).
      EXPECT_NEAR(double(t.mass[node]), child_mass, 4 * std::numeric_limits<Real>::epsilon() * child_mass);
    }
    // Keys of the node share its prefix.
    const unsigned shift = 3u * unsigned(LinearOctree<Real>::kLevels - level);
    const std::uint64_t pre = shift >= 64 ? 0 : keys[b] >> shift;
    EXPECT_EQ(pre, t.prefix[node]);
    EXPECT_EQ(shift >= 64 ? 0 : keys[e - 1] >> shift, t.prefix[node]);
    // Mass equals the sum of its particles; the centre of mass lies in the node's cube.
    double m = 0;
    for (std::uint32_t s = b; s < e; ++s) m += double(tree.m()[s]);
    EXPECT_NEAR(double(t.mass[node]), m, 1e-6 * m);
    const double cell = side / double(std::uint64_t(1) << level);
    std::array<double, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      std::uint64_t q = 0;
      for (int bit = 0; bit < level; ++bit) q |= ((t.prefix[node] >> (3 * bit + a)) & 1u) << bit;
      lo[std::size_t(a)] = corner[std::size_t(a)] + double(q) * cell;
      hi[std::size_t(a)] = lo[std::size_t(a)] + cell;
    }
    const double slack = 1e-5 * side;  // rounding of the centre to Real
    const std::array<double, 3> com{double(t.com_x[node]), double(t.com_y[node]), double(t.com_z[node])};
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(com[std::size_t(a)], lo[std::size_t(a)] - slack) << "node " << node;
      EXPECT_LE(com[std::size_t(a)], hi[std::size_t(a)] + slack) << "node " << node;
    }
  }
  for (int c : in_leaf) ASSERT_EQ(c, 1);
}

TYPED_TEST(LinearTreeTest, TreeInvariantsHoldForEveryBucketSize) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(3000);
  for (std::size_t bucket : {std::size_t(1), std::size_t(8), std::size_t(64)}) {
    SCOPED_TRACE(bucket);
    LinearOctree<Real> tree;
    tree.build(p, tree_settings(Multipole::Quadrupole, Criterion::Barnes, 0.5, 0.01, bucket), 100);
    check_invariants(tree, p, bucket);
    EXPECT_EQ(tree.depth(), LinearOctree<Real>::kLevels);  // the coincident clump reaches the finest level
  }
}

TYPED_TEST(LinearTreeTest, OpeningZeroIsTheDirectSum) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(1500);
  constexpr double eps = 0.01;
  GravityField<Real> direct;
  direct_sum(p, Real(eps), 64, direct);
  const double tol = std::is_same_v<Real, float> ? 2e-5 : 1e-12;
  for (Multipole mp : {Multipole::Monopole, Multipole::Quadrupole}) {
    for (Criterion cr : {Criterion::Paper, Criterion::Barnes}) {
      LinearOctree<Real> tree;
      tree.build(p, tree_settings(mp, cr, 0.0, eps, 8), 64);
      GravityField<Real> f;
      const WalkCounts counts = tree.evaluate(f, 64);
      EXPECT_EQ(counts.multipoles, 0u);
      EXPECT_EQ(counts.pairs, p.size() * (p.size() - 1));
      for (std::size_t i = 0; i < p.size(); ++i) {
        double d2 = 0, r2 = 0;
        for (int a = 0; a < 3; ++a) {
          const double d = double(f.acceleration[a][i]) - double(direct.acceleration[a][i]);
          d2 += d * d;
          r2 += double(direct.acceleration[a][i]) * double(direct.acceleration[a][i]);
        }
        ASSERT_LE(std::sqrt(d2), tol * std::sqrt(r2) + 1e-30) << i << " " << to_string(mp) << " " << to_string(cr);
        ASSERT_NEAR(f.potential[i], direct.potential[i], tol * std::abs(direct.potential[i])) << i;
      }
    }
  }
}

TYPED_TEST(LinearTreeTest, QuadrupoleIsMoreAccurateThanMonopoleAtEqualTheta) {
  using Real = TypeParam;
  constexpr double eps = 0.01;
  const ParticleSet<Real> p = plummer<Real>(4096, 2011);
  const ParticleSet<double> pd = testing::to_double(p);
  GravityField<double> ref;
  direct_sum(pd, eps, 64, ref);
  for (double theta : {0.5, 0.7}) {
    std::array<std::vector<double>, 2> errors;
    std::array<double, 2> potential_error{};
    for (Multipole mp : {Multipole::Monopole, Multipole::Quadrupole}) {
      LinearOctree<Real> tree;
      tree.build(p, tree_settings(mp, Criterion::Barnes, theta, eps), 64);
      GravityField<Real> f;
      tree.evaluate(f, 64);
      errors[std::size_t(mp)] = testing::relative_errors(f, ref, ref);
      double w = 0, w_ref = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        w += double(p.mass[i]) * double(f.potential[i]);
        w_ref += pd.mass[i] * ref.potential[i];
      }
      potential_error[std::size_t(mp)] = std::abs(w / w_ref - 1);
    }
    const auto& mono = errors[0];
    const auto& quad = errors[1];
    const double mono_median = quantile(mono, 0.5), quad_median = quantile(quad, 0.5);
    const double mono_p99 = quantile(mono, 0.99), quad_p99 = quantile(quad, 0.99);
    SCOPED_TRACE(theta);
    EXPECT_LE(mono_median, 0.04 * theta * theta);
    EXPECT_LE(quad_median, 0.04 * theta * theta * theta);
    EXPECT_LT(quad_median, 0.5 * mono_median);
    EXPECT_LT(quad_p99, mono_p99);
    // The potential comes from the same expansion: W is more accurate too.
    EXPECT_LT(potential_error[1], potential_error[0]);
    this->RecordProperty("theta_" + std::to_string(theta) + "_median_mono_quad",
                         std::to_string(mono_median) + " " + std::to_string(quad_median));
    this->RecordProperty("theta_" + std::to_string(theta) + "_p99_mono_quad",
                         std::to_string(mono_p99) + " " + std::to_string(quad_p99));
  }
}

// The paper's rule fails where Barnes' does not. The node C = [0, 1]³ (an
// octant of the root cube [−1, 1]³, fixed by two feather-weight anchors at
// its corners) holds a dense clump of mass 1 at its far corner (0.98, 0.98,
// 0.98) and one light particle (mass 0.01) at its near corner; the test
// particle sits just outside C, beside the light one. Its distance to C's
// centre of mass, d ≈ 1.77, makes l/d ≈ 0.57 < λ = 0.9: the paper accepts C
// and moves the light particle's strong pull to the far clump (error > 10 %,
// for the monopole and the quadrupole alike). Barnes' rule adds δ ≈ 0.81 (the
// centre of mass sits near the corner) to l/θ = 1.11 and opens C.
TYPED_TEST(LinearTreeTest, PaperRuleFailsOnAClumpAtACellCornerBarnesRuleDoesNot) {
  using Real = TypeParam;
  ParticleSet<Real> p;
  std::vector<std::array<double, 4>> particles;  // x, y, z, m
  particles.push_back({-1, -1, -1, 1e-9});  // anchors: the root cube is [−1, 1]³
  particles.push_back({1, 1, 1, 1e-9});
  const std::size_t clump = 200;
  for (std::size_t k = 0; k < clump; ++k) {
    const double u = double(k) / clump;  // a tiny ball of radius ~1e-3
    particles.push_back({0.98 + 1e-3 * std::cos(7 * u), 0.98 + 1e-3 * std::sin(11 * u), 0.98 + 1e-3 * (2 * u - 1),
                         1.0 / clump});
  }
  particles.push_back({0.02, 0.02, 0.02, 0.01});  // the light particle at C's near corner
  const std::size_t test = particles.size();
  particles.push_back({-0.05, -0.05, -0.05, 1e-6});  // the test particle, outside C
  p.resize(particles.size());
  for (std::size_t i = 0; i < particles.size(); ++i) {
    p.position.set(i, {Real(particles[i][0]), Real(particles[i][1]), Real(particles[i][2])});
    p.mass[i] = Real(particles[i][3]);
    p.id[i] = i;
  }
  constexpr double eps = 0;
  GravityField<double> ref;
  direct_sum(testing::to_double(p), eps, 64, ref);
  auto error_of = [&](Multipole mp, Criterion cr) {
    LinearOctree<Real> tree;
    tree.build(p, tree_settings(mp, cr, 0.9, eps), 64);
    GravityField<Real> f;
    tree.evaluate(f, 64);
    double d2 = 0, r2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = double(f.acceleration[a][test]) - ref.acceleration[a][test];
      d2 += d * d;
      r2 += ref.acceleration[a][test] * ref.acceleration[a][test];
    }
    return std::sqrt(d2 / r2);
  };
  for (Multipole mp : {Multipole::Monopole, Multipole::Quadrupole}) {
    SCOPED_TRACE(to_string(mp));
    EXPECT_GT(error_of(mp, Criterion::Paper), 0.10);
    EXPECT_LT(error_of(mp, Criterion::Barnes), 0.01);
  }
}

TYPED_TEST(LinearTreeTest, BitIdenticalForOneTwoAndThreeThreads) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(20000);
  const int saved = parallel::thread_count();
  std::vector<GravityField<Real>> fields;
  std::vector<WalkCounts> counts;
  std::vector<std::vector<Real>> quads;
  std::vector<ParticleSet<Real>> reordered;
  for (int threads : {1, 2, 3}) {
    parallel::set_thread_count(threads);
    LinearOctree<Real> tree;
    tree.build(p, tree_settings(Multipole::Quadrupole, Criterion::Barnes, 0.6, 0.01), 256);
    GravityField<Real> f;
    counts.push_back(tree.evaluate(f, 256));
    fields.push_back(std::move(f));
    quads.emplace_back(tree.nodes().qxy.begin(), tree.nodes().qxy.end());
    // Through the force model, reordering the particles along the curve.
    ParticleSet<Real> q = p;
    GravityForce<Real> force{GravitySettings{}};
    spatial::ParticleOrder<Real> order;
    swirl::evaluate_alone(force, q, order, 256);
    swirl::evaluate_alone(force, q, order, 256);
    reordered.push_back(std::move(q));
  }
  parallel::set_thread_count(saved);
  for (std::size_t k = 1; k < fields.size(); ++k) {
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(0, std::memcmp(fields[k].acceleration[a].data(), fields[0].acceleration[a].data(),
                               p.size() * sizeof(Real)));
    EXPECT_EQ(0, std::memcmp(fields[k].potential.data(), fields[0].potential.data(), p.size() * sizeof(Real)));
    EXPECT_EQ(counts[k].nodes, counts[0].nodes);
    EXPECT_EQ(counts[k].pairs, counts[0].pairs);
    EXPECT_EQ(quads[k], quads[0]);
    EXPECT_TRUE(testing::same_bits(reordered[k], reordered[0]));
  }
}

TYPED_TEST(LinearTreeTest, TheSolverViewsTheSharedOrderAndIdsSurvive) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(3000, 5);
  GravitySettings g;  // the default: global scheme, linear tree, quadrupole, Barnes' rule
  ASSERT_EQ(g.tree, Tree::Linear);
  // The field the tree computes without moving the particles...
  BarnesHut<Real> still(g);
  GravityField<Real> expected;
  still.compute(p, expected, 128);
  // ...is the solver's, found by id after the shared order moved them along the curve.
  ParticleSet<Real> q = p;
  GravityForce<Real> force(g);
  swirl::evaluate_alone(force, q, 128);
  EXPECT_GT(force.stats().tree_bytes, 0u);
  EXPECT_GT(force.stats().mean_interactions, 0.0);
  bool moved = false;
  std::vector<int> seen(p.size(), 0);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const std::size_t j = q.id[i];  // plummer() sets id = index
    ASSERT_LT(j, p.size());
    ++seen[j];
    moved = moved || j != i;
    ASSERT_EQ(q.position.get(i), p.position.get(j));
    ASSERT_EQ(q.velocity.get(i), p.velocity.get(j));
    ASSERT_EQ(q.mass[i], p.mass[j]);
    ASSERT_EQ(q.acceleration.x[i], expected.acceleration.x[j]);
    ASSERT_EQ(q.acceleration.z[i], expected.acceleration.z[j]);
  }
  EXPECT_TRUE(moved);
  for (int c : seen) ASSERT_EQ(c, 1);
  // In curve order now: a second build finds the identity permutation.
  LinearOctree<Real> again;
  again.build(q, tree_settings(g.multipole, g.criterion, g.opening, g.softening), 128);
  for (std::size_t s = 0; s < q.size(); ++s) ASSERT_EQ(again.order()[s], s);
}

TYPED_TEST(LinearTreeTest, EmptyAndSingleParticleSets) {
  using Real = TypeParam;
  LinearOctree<Real> tree;
  GravityField<Real> f;
  tree.build(ParticleSet<Real>(), LinearTreeSettings{}, 64);
  EXPECT_EQ(tree.evaluate(f, 64).nodes, 0u);
  EXPECT_EQ(f.size(), 0u);
  ParticleSet<Real> one(1);
  one.mass[0] = 1;
  tree.build(one, LinearTreeSettings{}, 64);
  tree.evaluate(f, 64);
  EXPECT_EQ(f.acceleration.get(0), Vec3<Real>{});
  EXPECT_EQ(f.potential[0], Real(0));
}

}  // namespace
}  // namespace swirl::gravity
