// Gravity scenes: [nbody] and the self-gravitating particle models.
#include <gtest/gtest.h>

#include <string>

#include "swirl/gravity/disk_galaxy.hpp"
#include "swirl/gravity/spherical_models.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"

namespace {

using namespace swirl::scene;

const std::string kPlummer = R"(
[simulation]
dt = 0.01
steps = 10

[nbody]
scheme = "subtree"
opening = 0.7
softening = 0.02

[[particles]]
kind = "plummer"
count = 1000
seed = 3
)";

std::string error_of(const std::string& text, std::vector<std::string> overrides = {}) {
  try {
    parse_scene(text, "g.toml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(NbodyScene, PlummerSceneParsesIntoOpenSpaceInDouble) {
  const Scene s = parse_scene(kPlummer, "g.toml");
  ASSERT_TRUE(s.nbody);
  EXPECT_EQ(s.nbody->scheme, swirl::gravity::Scheme::Subtree);
  EXPECT_EQ(s.nbody->method, swirl::gravity::Method::BarnesHut);
  EXPECT_EQ(s.nbody->opening, 0.7);
  EXPECT_EQ(s.nbody->softening, 0.02);
  EXPECT_EQ(s.nbody->subdomain_size, 208u);
  EXPECT_EQ(s.nbody->subtree_nodes, 370u);
  EXPECT_EQ(s.nbody->subtree_split, swirl::gravity::SubtreeSplit::Units);
  EXPECT_EQ(s.nbody->upper_nodes, swirl::gravity::UpperNodes::Opened);
  EXPECT_FALSE(s.walls);
  EXPECT_EQ(s.precision, Precision::Double);
  EXPECT_EQ(s.gravity, swirl::Vec3d{});
  const auto p = make_particles<double>(s);
  ASSERT_EQ(p.size(), 1000u);
  double mass = 0;
  for (std::size_t i = 0; i < p.size(); ++i) mass += p.mass[i];
  EXPECT_NEAR(mass, 1.0, 1e-12);
  // The same seed gives the same particles; precision can be chosen.
  EXPECT_EQ(make_particles<double>(s).position.x, p.position.x);
  const auto f = make_particles<float>(parse_scene(kPlummer, "g.toml", std::vector<std::string>{"simulation.precision=\"float\""}));
  EXPECT_EQ(f.size(), 1000u);
}

TEST(NbodyScene, ThePapersSplitsAreSceneKeys) {
  const Scene s = parse_scene(kPlummer, "g.toml",
                              std::vector<std::string>{"nbody.subtree_split=\"parts\"", "nbody.subtree_parts=16",
                                                       "nbody.upper_nodes=\"clusters\"",
                                                       "nbody.subdomain_split=\"paper\""});
  EXPECT_EQ(s.nbody->subtree_split, swirl::gravity::SubtreeSplit::Parts);
  EXPECT_EQ(s.nbody->subtree_parts, 16u);
  EXPECT_EQ(s.nbody->upper_nodes, swirl::gravity::UpperNodes::Clusters);
  EXPECT_EQ(s.nbody->subdomain_split, swirl::gravity::SubdomainSplit::Paper);
  const std::string e = error_of(kPlummer, {"nbody.upper_nodes=\"shared\""});
  EXPECT_NE(e.find("nbody.upper_nodes"), std::string::npos) << e;
  EXPECT_NE(e.find("'clusters'"), std::string::npos) << e;
  EXPECT_NE(error_of(kPlummer, {"nbody.subtree_parts=0"}).find("nbody.subtree_parts"), std::string::npos);
}

TEST(NbodyScene, TheFastMultipoleMethodIsAMethodWithAnOrder) {
  const Scene s = parse_scene(kPlummer, "g.toml",
                              std::vector<std::string>{"nbody.method=\"fmm\"", "nbody.scheme=\"global\"",
                                                       "nbody.fmm_order=5"});
  EXPECT_EQ(s.nbody->method, swirl::gravity::Method::Fmm);
  EXPECT_EQ(s.nbody->fmm_order, 5u);
  EXPECT_EQ(s.nbody->tree, swirl::gravity::Tree::Linear);
  EXPECT_EQ(parse_scene(kPlummer, "g.toml").nbody->fmm_order, 3u);
}

TEST(NbodyScene, ModelsAreMovedByOffsetAndVelocity) {
  const Scene s = parse_scene(kPlummer + R"(
[[particles]]
kind = "uniform_sphere"
count = 500
radius = 2.0
mass = 3.0
offset = [10.0, 0.0, 0.0]
velocity = [0.0, 1.0, 0.0]
)", "g.toml");
  const auto p = make_particles<double>(s);
  ASSERT_EQ(p.size(), 1500u);
  double mass = 0, x = 0, vy = 0;
  for (std::size_t i = 1000; i < 1500; ++i) {
    mass += p.mass[i];
    x += p.mass[i] * p.position.x[i];
    vy += p.mass[i] * p.velocity.y[i];
    EXPECT_LE(std::hypot(p.position.x[i] - 10.0, p.position.y[i], p.position.z[i]), 2.0 + 1e-12);
    EXPECT_EQ(p.id[i], i);
  }
  EXPECT_NEAR(mass, 3.0, 1e-12);
  EXPECT_NEAR(x / mass, 10.0, 0.2);
  EXPECT_NEAR(vy / mass, 1.0, 1e-12);
}

TEST(NbodyScene, BadGravityInputIsRefusedClearly) {
  EXPECT_EQ(error_of(kPlummer, {"nbody.opening=1.5"}), "g.toml: nbody.opening: must be in [0, 1], got 1.5");
  EXPECT_EQ(error_of(kPlummer, {"nbody.opening=-0.1"}), "g.toml: nbody.opening: must be in [0, 1], got -0.1");
  EXPECT_EQ(error_of(kPlummer, {"nbody.softening=-0.01"}), "g.toml: nbody.softening: must be >= 0, got -0.01");
  EXPECT_EQ(error_of(kPlummer, {"particles.0.count=0"}), "g.toml: particles[0].count: must be in [1, 2147483648], got 0");
  EXPECT_EQ(error_of(kPlummer, {"nbody.scheme=\"octree\""}),
            "g.toml: nbody.scheme: unknown scheme 'octree' (allowed: 'subdomain', 'subtree', 'global')");
  EXPECT_EQ(error_of(kPlummer, {"nbody.method=\"pm\""}),
            "g.toml: nbody.method: unknown method 'pm' (allowed: 'direct', 'barnes_hut', 'fmm')");
  EXPECT_EQ(error_of(kPlummer, {"nbody.method=\"fmm\"", "nbody.fmm_order=6"}),
            "g.toml: nbody.fmm_order: must be in [2, 5], got 6");
  EXPECT_EQ(error_of(kPlummer, {"nbody.method=\"fmm\"", "nbody.fmm_order=1"}),
            "g.toml: nbody.fmm_order: must be in [2, 5], got 1");
  EXPECT_EQ(error_of(kPlummer, {"nbody.method=\"fmm\"", "nbody.scheme=\"subtree\""}),
            "g.toml: nbody.scheme: \"subtree\" is a Barnes-Hut scheme; method \"fmm\" needs scheme = \"global\"");
  EXPECT_EQ(error_of(kPlummer, {"nbody.method=\"fmm\"", "nbody.scheme=\"global\"", "nbody.tree=\"paper\""}),
            "g.toml: nbody.tree: method \"fmm\" walks the linear octree: needs tree = \"linear\"");
  EXPECT_EQ(error_of(kPlummer, {"nbody.theta=0.5"}), "g.toml: nbody.theta: unknown key");
  EXPECT_EQ(error_of(kPlummer, {"nbody.opneing=0.5"}), "g.toml: nbody.opneing: unknown key (did you mean 'opening'?)");
  EXPECT_NE(error_of(kPlummer + "[box]\nmin = [-5, -5, -5]\nmax = [5, 5, 5]\n").find("needs open space"), std::string::npos);
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"plummer_collision\"", "particles.0.impact_parameter=20"}),
            "g.toml: particles[0].impact_parameter: must be in [0, 10), got 20");
}

TEST(NbodyScene, NfwAndKingAreSceneKindsWithTheirOptions) {
  const Scene s = parse_scene(kPlummer + R"(
[[particles]]
kind = "nfw"
count = 300
seed = 5
concentration = 5
decay = 0.2
virial_radius = 3

[[particles]]
kind = "king"
count = 200
seed = 6
w0 = 9
offset = [20.0, 0.0, 0.0]
)", "g.toml");
  const auto p = make_particles<double>(s);
  ASSERT_EQ(p.size(), 1500u);
  // The scene's particles are the generators' with the scene's options, moved by offset.
  const auto halo = swirl::gravity::nfw<double>(300, 5, {.concentration = 5, .decay = 0.2, .virial_radius = 3.0});
  const auto cluster = swirl::gravity::king<double>(200, 6, {.w0 = 9});
  for (std::size_t i = 0; i < 300; ++i) {
    EXPECT_EQ(p.position.x[1000 + i], halo.position.x[i]);
    EXPECT_EQ(p.velocity.z[1000 + i], halo.velocity.z[i]);
  }
  for (std::size_t i = 0; i < 200; ++i) {
    EXPECT_EQ(p.position.x[1300 + i], cluster.position.x[i] + 20.0);
    EXPECT_EQ(p.velocity.y[1300 + i], cluster.velocity.y[i]);
  }
  // Defaults: c = 10, decay 0.1, Hénon units; W₀ = 6.
  const Scene d = parse_scene(kPlummer, "g.toml", std::vector<std::string>{"particles.0.kind=\"nfw\""});
  EXPECT_EQ(make_particles<double>(d).position.y, swirl::gravity::nfw<double>(1000, 3).position.y);
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"king\"", "particles.0.w0=20"}),
            "g.toml: particles[0].w0: must be in [0.1, 16], got 20");
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"nfw\"", "particles.0.concentration=0.5"}),
            "g.toml: particles[0].concentration: must be in [1, 100], got 0.5");
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"nfw\"", "particles.0.virial_radius=0"}),
            "g.toml: particles[0].virial_radius: must be > 0, got 0");
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"king\"", "particles.0.concentration=5"}),
            "g.toml: particles[0].concentration: unknown key for kind 'king'");
}

TEST(NbodyScene, DiskGalaxyIsASceneKindWithItsOptions) {
  const Scene s = parse_scene(kPlummer, "g.toml",
                              std::vector<std::string>{"particles.0.kind=\"disk_galaxy\"", "particles.0.disk_mass=0.1",
                                                       "particles.0.toomre_q=2", "particles.0.disk_particles=0.25"});
  swirl::gravity::DiskGalaxyOptions o;
  o.disk_mass = 0.1;
  o.toomre_q = 2;
  o.disk_particles = 0.25;
  const auto p = make_particles<double>(s);
  const auto direct = swirl::gravity::disk_galaxy<double>(1000, 3, o);
  EXPECT_EQ(p.position.z, direct.position.z);
  EXPECT_EQ(p.velocity.x, direct.velocity.x);
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"disk_galaxy\"", "particles.0.disk_particles=0.0001"}),
            "g.toml: particles[0].disk_particles: 0.0001 of 1000 particles leaves the disk or the halo empty");
  EXPECT_EQ(error_of(kPlummer, {"particles.0.kind=\"disk_galaxy\"", "particles.0.disk_cut=1"}),
            "g.toml: particles[0].disk_cut: must be in [2, 50], got 1");
}

}  // namespace
