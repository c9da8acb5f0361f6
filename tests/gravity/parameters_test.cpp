// Bad parameters are clear std::invalid_argument errors naming the parameter.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/bench.hpp"
#include "swirl/gravity/direct_sum.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class ParametersTest : public ::testing::Test {};
TYPED_TEST_SUITE(ParametersTest, testing::Precisions);

// Runs f, expects std::invalid_argument whose message contains every word.
template <class F>
void expect_invalid(F f, std::initializer_list<const char*> words) {
  try {
    f();
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    for (const char* w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

TYPED_TEST(ParametersTest, OpeningAngleOutsideZeroToOne) {
  using Real = TypeParam;
  for (double lambda : {-0.1, 1.01, std::numeric_limits<double>::quiet_NaN()}) {
    GravitySettings s;
    s.opening = lambda;
    expect_invalid([&] { GravityForce<Real> g(s); }, {"lambda", "[0, 1]"});
  }
  GravitySettings edge;
  for (double lambda : {0.0, 1.0}) {
    edge.opening = lambda;
    EXPECT_NO_THROW(GravityForce<Real>{edge});
  }
}

TYPED_TEST(ParametersTest, NegativeOrNonFiniteSoftening) {
  using Real = TypeParam;
  for (double eps : {-1e-3, std::numeric_limits<double>::infinity()}) {
    GravitySettings s;
    s.softening = eps;
    expect_invalid([&] { GravityForce<Real> g(s); }, {"softening", ">= 0"});
  }
  const ParticleSet<Real> p = plummer<Real>(4, 1);
  GravityField<Real> f;
  expect_invalid([&] { direct_sum(p, Real(-1), 1, f); }, {"softening"});
}

TYPED_TEST(ParametersTest, ZeroSizes) {
  using Real = TypeParam;
  GravitySettings s;
  s.subdomain_size = 0;
  expect_invalid([&] { GravityForce<Real> g(s); }, {"subdomain_size"});
  s = {};
  s.subtree_nodes = 0;
  expect_invalid([&] { GravityForce<Real> g(s); }, {"subtree_nodes"});
  s = {};
  s.bucket_size = 0;
  expect_invalid([&] { GravityForce<Real> g(s); }, {"bucket_size"});
  s = {};
  s.subtree_parts = 0;
  expect_invalid([&] { GravityForce<Real> g(s); }, {"subtree_parts"});
}

TEST(ParametersTest, TreeMultipoleAndCriterionNamesRoundTrip) {
  for (Tree t : {Tree::Paper, Tree::Linear}) EXPECT_EQ(parse_tree(to_string(t)), t);
  for (Multipole m : {Multipole::Monopole, Multipole::Quadrupole}) EXPECT_EQ(parse_multipole(to_string(m)), m);
  for (Criterion c : {Criterion::Paper, Criterion::Barnes}) EXPECT_EQ(parse_criterion(to_string(c)), c);
  expect_invalid([] { (void)parse_tree("kd"); }, {"tree", "kd", "\"paper\"", "\"linear\""});
  expect_invalid([] { (void)parse_multipole("octupole"); }, {"octupole", "\"monopole\"", "\"quadrupole\""});
  expect_invalid([] { (void)parse_criterion("bmax"); }, {"bmax", "\"paper\"", "\"barnes\""});
  for (SubdomainSplit v : {SubdomainSplit::Adaptive, SubdomainSplit::Paper})
    EXPECT_EQ(parse_subdomain_split(to_string(v)), v);
  for (SubtreeSplit v : {SubtreeSplit::Units, SubtreeSplit::Parts}) EXPECT_EQ(parse_subtree_split(to_string(v)), v);
  for (UpperNodes v : {UpperNodes::Opened, UpperNodes::Clusters}) EXPECT_EQ(parse_upper_nodes(to_string(v)), v);
  expect_invalid([] { (void)parse_upper_nodes("shared"); }, {"shared", "\"opened\"", "\"clusters\""});
  // The defaults of the issue: the linear tree, quadrupoles, Barnes' rule.
  const GravitySettings s;
  EXPECT_EQ(s.scheme, Scheme::Global);
  EXPECT_EQ(s.tree, Tree::Linear);
  EXPECT_EQ(s.multipole, Multipole::Quadrupole);
  EXPECT_EQ(s.criterion, Criterion::Barnes);
}

TEST(ParametersTest, UnknownSchemeOrMethodListsTheAllowedNames) {
  expect_invalid([] { (void)parse_scheme("quadtree"); }, {"quadtree", "\"subdomain\"", "\"subtree\"", "\"global\""});
  expect_invalid([] { (void)parse_method("p3m"); }, {"p3m", "\"direct\"", "\"barnes_hut\"", "\"fmm\""});
  for (Scheme s : testing::kSchemes) EXPECT_EQ(parse_scheme(to_string(s)), s);
  EXPECT_EQ(parse_method("direct"), Method::Direct);
  EXPECT_EQ(parse_method("barnes_hut"), Method::BarnesHut);
  EXPECT_EQ(parse_method("fmm"), Method::Fmm);
}

TYPED_TEST(ParametersTest, NoParticlesOrBadShapesForInitialConditions) {
  using Real = TypeParam;
  expect_invalid([] { plummer<Real>(0, 1); }, {"plummer", "particle count"});
  expect_invalid([] { uniform_sphere<Real>(0, 1); }, {"uniform_sphere", "particle count"});
  expect_invalid([] { uniform_cube<Real>(0, 1); }, {"uniform_cube", "particle count"});
  expect_invalid([] { cold_collapse<Real>(0, 1); }, {"cold_collapse", "particle count"});
  expect_invalid([] { plummer_collision<Real>(0, 1); }, {"plummer_collision", "particle count"});
  expect_invalid([] { plummer<Real>(10, 1, {1.5}); }, {"mass_cut"});
  expect_invalid([] { uniform_sphere<Real>(10, 1, -1.0); }, {"radius"});
  expect_invalid([] { uniform_cube<Real>(10, 1, 0.0); }, {"side"});
  CollisionOptions o;
  o.mass_fraction = 1;
  expect_invalid([&] { plummer_collision<Real>(10, 1, o); }, {"mass_fraction"});
  o = {};
  o.impact_parameter = 10;
  expect_invalid([&] { plummer_collision<Real>(10, 1, o); }, {"impact_parameter"});
  o = {};
  o.relative_velocity = -1;
  expect_invalid([&] { plummer_collision<Real>(10, 1, o); }, {"relative_velocity"});
  o = {};
  o.mass_fraction = 0.01;  // no particle left for the small sphere
  expect_invalid([&] { plummer_collision<Real>(10, 1, o); }, {"at least one per sphere"});
}

TEST(ParametersTest, BenchRejectsBadSettings) {
  BenchSettings b;
  b.n = 0;
  expect_invalid([&] { time_iterations(b); }, {"particle count"});
  b = {};
  b.threads = 0;
  expect_invalid([&] { time_iterations(b); }, {"threads"});
  b = {};
  b.opening = 2;
  expect_invalid([&] { time_iterations(b); }, {"lambda"});
}

}  // namespace
}  // namespace swirl::gravity
