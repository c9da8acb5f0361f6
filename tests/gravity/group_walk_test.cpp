// The linear octree's group walk (linear_octree.hpp, Walk::Group) against its
// slow twins: the direct sum (θ = 0) and the per-particle walk (Walk::Particle)
// at equal θ. The group's opening test (centre of mass to the group's bounding
// box) is at least as strict as the per-particle one for every particle of the
// group, so its interaction lists are refinements of the per-particle ones:
// never fewer interactions, and never a worse force error in the median, the
// 99th percentile or the maximum (checked on a Plummer sphere and on two
// Plummer spheres on a collision orbit, for both criteria and multipoles).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "gravity/gravity_test_util.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/gravity/linear_octree.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {
namespace {

using testing::quantile;

template <class Real>
class GroupWalkTest : public ::testing::Test {};
TYPED_TEST_SUITE(GroupWalkTest, testing::Precisions);

LinearTreeSettings walk_settings(Walk walk, Multipole multipole, Criterion criterion, double opening,
                                 std::size_t bucket = 16, std::size_t group = 64) {
  LinearTreeSettings s;
  s.walk = walk;
  s.multipole = multipole;
  s.criterion = criterion;
  s.opening = opening;
  s.softening = 0.01;
  s.bucket_size = bucket;
  s.group_size = group;
  return s;
}

// A Plummer sphere with a clump of 100 coincident particles (one finest-level
// leaf, larger than any group here) and an outlier far away.
template <class Real>
ParticleSet<Real> awkward_set(std::size_t n) {
  ParticleSet<Real> p = plummer<Real>(n, 7);
  for (std::size_t i = 0; i < 100; ++i) p.position.set(i, {Real(0.25), Real(-0.5), Real(0.125)});
  p.position.set(100, {Real(40), Real(-30), Real(10)});
  return p;
}

template <class Real>
bool same_field_bits(const GravityField<Real>& a, const GravityField<Real>& b) {
  return testing::same_bits(a, b);
}

// |a − ref| / |ref| per particle (not sorted).
template <class Real>
std::vector<double> errors_of(const GravityField<Real>& f, const GravityField<double>& ref) {
  std::vector<double> e(ref.size());
  for (std::size_t i = 0; i < e.size(); ++i) {
    double d2 = 0, r2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = double(f.acceleration[a][i]) - ref.acceleration[a][i];
      d2 += d * d;
      r2 += ref.acceleration[a][i] * ref.acceleration[a][i];
    }
    e[i] = std::sqrt(d2 / r2);
  }
  return e;
}

TYPED_TEST(GroupWalkTest, GroupsCoverEveryParticleOnceInCurveOrder) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(3000);
  for (std::size_t group : {std::size_t(1), std::size_t(16), std::size_t(64), std::size_t(5000)}) {
    SCOPED_TRACE(group);
    LinearOctree<Real> tree;
    tree.build(p, walk_settings(Walk::Group, Multipole::Quadrupole, Criterion::Barnes, 0.5, 8, group), 64);
    const auto& t = tree.nodes();
    std::uint32_t next = 0;
    for (std::uint32_t g : tree.groups()) {
      ASSERT_EQ(t.begin[g], next);
      next = t.end[g];
      const std::size_t size = t.end[g] - t.begin[g];
      if (t.child_count[g] != 0) {
        EXPECT_LE(size, group);  // a subtree; only a leaf may exceed the group size
      }
    }
    EXPECT_EQ(next, p.size());
  }
}

// θ = 0 opens every node: the group walk adds exactly the direct sum's terms
// (in another order), as tight as the per-particle walk's own test with the
// kernels' scalar path, and to the SIMD kernels' round-off with every ISA.
TYPED_TEST(GroupWalkTest, OpeningZeroIsTheDirectSum) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(1000);
  GravityField<Real> direct;
  direct_sum(p, Real(0.01), 64, direct);
  auto check = [&](const LinearTreeSettings& s, double tol) {
    LinearOctree<Real> tree;
    tree.build(p, s, 64);
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
      ASSERT_LE(std::sqrt(d2), tol * std::sqrt(r2) + 1e-30) << i;
      ASSERT_NEAR(f.potential[i], direct.potential[i], tol * std::abs(direct.potential[i])) << i;
    }
  };
  const bool is_float = std::is_same_v<Real, float>;
  for (Multipole mp : {Multipole::Monopole, Multipole::Quadrupole}) {
    for (Criterion cr : {Criterion::Paper, Criterion::Barnes}) {
      for (std::size_t group : {std::size_t(1), std::size_t(32), std::size_t(64)}) {
        SCOPED_TRACE(std::string(to_string(mp)) + " " + std::string(to_string(cr)) + " group " + std::to_string(group));
        LinearTreeSettings s = walk_settings(Walk::Group, mp, cr, 0.0, 8, group);
        s.simd_kernels = false;
        check(s, is_float ? 2e-5 : 1e-12);
        if (mp != Multipole::Quadrupole || group != 32) continue;  // the SIMD paths once (quick under ASan)
        s.simd_kernels = true;
        for (simd::Isa isa : simd::kCompiledIsas) {
          if (!simd::usable(isa)) continue;
          SCOPED_TRACE(simd::isa_name(isa));
          const simd::ScopedIsa scoped(isa);
          check(s, is_float ? 2e-5 : 1e-12);
        }
      }
    }
  }
}

// The group walk never does worse than the per-particle walk at equal θ, and
// costs at least as many interactions.
template <class Real>
void expect_no_worse_than_particle_walk(const ParticleSet<Real>& p, const char* name) {
  GravityField<double> ref;
  direct_sum(testing::to_double(p), 0.01, 64, ref);
  for (Multipole mp : {Multipole::Monopole, Multipole::Quadrupole}) {
    for (Criterion cr : {Criterion::Paper, Criterion::Barnes}) {
      for (double theta : {0.5, 0.8}) {
        SCOPED_TRACE(std::string(name) + " " + std::string(to_string(mp)) + " " + std::string(to_string(cr)) +
                     " theta " + std::to_string(theta));
        std::vector<double> err[2];
        WalkCounts counts[2];
        for (Walk walk : {Walk::Particle, Walk::Group}) {
          LinearOctree<Real> tree;
          tree.build(p, walk_settings(walk, mp, cr, theta), 64);
          GravityField<Real> f;
          counts[std::size_t(walk)] = tree.evaluate(f, 64);
          err[std::size_t(walk)] = errors_of(f, ref);
        }
        const auto& g = err[std::size_t(Walk::Group)];
        const auto& q = err[std::size_t(Walk::Particle)];
        const WalkCounts& cg = counts[std::size_t(Walk::Group)];
        const WalkCounts& cq = counts[std::size_t(Walk::Particle)];
        EXPECT_GE(cg.pairs + cg.multipoles, cq.pairs + cq.multipoles);
        EXPECT_GE(cg.pairs, cq.pairs);
        // Round-off of the sums (float: the kernels' 1/sqrt as well).
        const double slack = std::is_same_v<Real, float> ? 2e-5 : 1e-12;
        std::size_t better = 0;
        for (std::size_t i = 0; i < g.size(); ++i) better += g[i] <= q[i] + slack ? 1 : 0;
        std::vector<double> gs = g, qs = q;
        std::sort(gs.begin(), gs.end());
        std::sort(qs.begin(), qs.end());
        EXPECT_LE(quantile(gs, 0.5), quantile(qs, 0.5) + slack);
        EXPECT_LE(quantile(gs, 0.99), quantile(qs, 0.99) + slack);
        EXPECT_LE(gs.back(), qs.back() + slack);
        // Opening more nodes can, for a few particles, remove an error that
        // happened to cancel another; most particles are at least as accurate.
        EXPECT_GE(double(better), 0.8 * double(g.size()));
        ::testing::Test::RecordProperty(
            std::string(name) + "_" + std::string(to_string(mp)) + "_" + std::string(to_string(cr)) + "_" +
                std::to_string(theta),
            "median " + std::to_string(quantile(gs, 0.5)) + " vs " + std::to_string(quantile(qs, 0.5)) + ", p99 " +
                std::to_string(quantile(gs, 0.99)) + " vs " + std::to_string(quantile(qs, 0.99)) + ", better " +
                std::to_string(double(better) / double(g.size())));
      }
    }
  }
}

TYPED_TEST(GroupWalkTest, NeverWorseThanTheParticleWalkOnAPlummerSphere) {
  expect_no_worse_than_particle_walk(plummer<TypeParam>(3000, 2011), "plummer");
}

TYPED_TEST(GroupWalkTest, NeverWorseThanTheParticleWalkOnTwoCollidingGalaxies) {
  CollisionOptions o;
  o.separation = 4;  // close enough that each galaxy's groups see the other's nodes at a range of distances
  o.mass_fraction = 0.3;
  expect_no_worse_than_particle_walk(plummer_collision<TypeParam>(3000, 5, o), "collision");
}

// Bit-identical for 1, 2 and 3 threads, and across repeated evaluations whose
// hand-out order changes (the first by particle count, later ones by cost),
// also after a rebuild (the costs then are carried over as an estimate).
TYPED_TEST(GroupWalkTest, BitIdenticalForOneTwoAndThreeThreadsAndAnyOrder) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(5000);
  ParticleSet<Real> moved = p;
  for (std::size_t i = 0; i < moved.size(); ++i) moved.position.x[i] += Real(1e-3) * moved.position.y[i];
  const int saved = parallel::thread_count();
  std::vector<GravityField<Real>> fields;
  std::vector<WalkCounts> counts;
  for (int threads : {1, 2, 3}) {
    SCOPED_TRACE(threads);
    parallel::set_thread_count(threads);
    LinearOctree<Real> tree;
    tree.build(p, walk_settings(Walk::Group, Multipole::Quadrupole, Criterion::Barnes, 0.6, 16, 32), 256);
    GravityField<Real> first, second, rebuilt;
    counts.push_back(tree.evaluate(first, 256));
    const std::vector<std::uint32_t> schedule1(tree.group_schedule().begin(), tree.group_schedule().end());
    const WalkCounts again = tree.evaluate(second, 256);
    const std::vector<std::uint32_t> schedule2(tree.group_schedule().begin(), tree.group_schedule().end());
    EXPECT_NE(schedule1, schedule2);  // the order did change
    EXPECT_TRUE(same_field_bits(first, second));
    EXPECT_EQ(again.pairs, counts.back().pairs);
    EXPECT_EQ(again.multipoles, counts.back().multipoles);
    EXPECT_EQ(again.nodes, counts.back().nodes);
    // A fresh tree on moved particles with the old costs against one without.
    const LinearTreeSettings same = tree.settings();
    tree.build(moved, same, 256);
    tree.evaluate(rebuilt, 256);
    LinearOctree<Real> fresh;
    fresh.build(moved, same, 256);
    GravityField<Real> fresh_field;
    fresh.evaluate(fresh_field, 256);
    EXPECT_TRUE(same_field_bits(rebuilt, fresh_field));
    fields.push_back(std::move(first));
    fields.push_back(std::move(rebuilt));
  }
  parallel::set_thread_count(saved);
  for (std::size_t k = 2; k < fields.size(); ++k) EXPECT_TRUE(same_field_bits(fields[k], fields[k % 2])) << k;
  for (const WalkCounts& c : counts) {
    EXPECT_EQ(c.pairs, counts[0].pairs);
    EXPECT_EQ(c.multipoles, counts[0].multipoles);
    EXPECT_EQ(c.nodes, counts[0].nodes);
  }
}

// The kernels' SIMD path against their scalar path through the whole walk.
TYPED_TEST(GroupWalkTest, SimdKernelsMatchTheScalarPathThroughTheWalk) {
  using Real = TypeParam;
  const ParticleSet<Real> p = plummer<Real>(4000, 3);
  LinearTreeSettings s = walk_settings(Walk::Group, Multipole::Quadrupole, Criterion::Barnes, 0.7);
  s.simd_kernels = false;
  LinearOctree<Real> scalar_tree;
  scalar_tree.build(p, s, 64);
  GravityField<Real> scalar;
  scalar_tree.evaluate(scalar, 64);
  s.simd_kernels = true;
  const double tol = std::is_same_v<Real, float> ? 2e-5 : 1e-12;
  for (simd::Isa isa : simd::kCompiledIsas) {
    if (!simd::usable(isa)) continue;
    SCOPED_TRACE(simd::isa_name(isa));
    const simd::ScopedIsa scoped(isa);
    LinearOctree<Real> tree;
    tree.build(p, s, 64);
    GravityField<Real> f;
    tree.evaluate(f, 64);
    for (std::size_t i = 0; i < p.size(); ++i) {
      double d2 = 0, r2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double d = double(f.acceleration[a][i]) - double(scalar.acceleration[a][i]);
        d2 += d * d;
        r2 += double(scalar.acceleration[a][i]) * double(scalar.acceleration[a][i]);
      }
      ASSERT_LE(std::sqrt(d2), tol * std::sqrt(r2)) << i;
      ASSERT_NEAR(f.potential[i], scalar.potential[i], tol * std::abs(scalar.potential[i])) << i;
    }
  }
}

// The walk's work per particle (add_walk_costs, what MPI ranks balance by):
// each particle's interaction-list length, summing to the walk's counts.
TYPED_TEST(GroupWalkTest, WalkCostsAreEachParticlesListLength) {
  using Real = TypeParam;
  const ParticleSet<Real> p = awkward_set<Real>(2000);
  LinearOctree<Real> tree;
  tree.build(p, walk_settings(Walk::Group, Multipole::Quadrupole, Criterion::Barnes, 0.6), 64);
  GravityField<Real> f;
  const WalkCounts counts = tree.evaluate(f, 64);
  std::vector<std::uint64_t> costs(p.size(), 1);
  tree.add_walk_costs(costs);
  std::uint64_t total = 0;
  for (const std::uint64_t c : costs) {
    EXPECT_GE(c, 2u);
    EXPECT_LE(c, p.size());  // 1 + at most every other particle
    total += c - 1;
  }
  EXPECT_EQ(total, counts.multipoles + counts.pairs);
  // The clump (one leaf larger than a group) shares one list: one cost.
  for (std::size_t i = 1; i < 100; ++i) EXPECT_EQ(costs[i], costs[0]);
  std::vector<std::uint64_t> wrong(p.size() - 1);
  EXPECT_THROW(tree.add_walk_costs(wrong), std::logic_error);
}

TEST(GroupWalkSettings, WalkNamesParseAndBadNamesAreRefused) {
  EXPECT_EQ(parse_walk("group"), Walk::Group);
  EXPECT_EQ(parse_walk("particle"), Walk::Particle);
  EXPECT_EQ(to_string(Walk::Group), "group");
  try {
    parse_walk("per-group");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("walk"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("particle"), std::string::npos);
  }
  GravitySettings g;
  EXPECT_EQ(g.walk, Walk::Group);
  g.group_size = 0;
  EXPECT_THROW(validate(g), std::invalid_argument);
  LinearOctree<double> tree;
  LinearTreeSettings s;
  s.group_size = 0;
  EXPECT_THROW(tree.build(plummer<double>(10, 1), s, 64), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::gravity
