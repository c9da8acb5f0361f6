// A Plummer sphere of 2048 particles over 10 crossing times (t = 28.3, Hénon
// units) with the stepper's leapfrog: the linear tree (quadrupole, Barnes'
// rule, θ = 0.5, the defaults) conserves energy as well as the baseline (the
// paper's tree, global scheme, λ = 0.5) on the same particles, in float and
// double, and the particles are reordered along the curve at every step.
//
// Set-up and bound as equilibrium_long_test.cpp: ε = 0.05, Δt = 1/64, so
// |ΔE/E| ≤ 4.8·10⁻⁴ (leapfrog at the fastest frequencies) + 2·10⁻³ (the walk's
// φ offset changing with the tree) = 2.5·10⁻³ for either tree. "As well as
// the baseline": the linear tree's worst energy error is at most 1.5 times
// the baseline's plus 10⁻⁴ — leapfrog's own error, common to both, dominates
// (the force error of either tree at θ = λ = 0.5 is ≲ 10⁻³ per particle and
// does not accumulate in a symplectic step). The virial ratio stays within
// 0.1 of 1 with the linear tree. (Measured, float and double: worst |ΔE/E|
// 5·10⁻⁵ with the linear tree, 8–9·10⁻⁴ with the paper's: the quadrupole's
// potential moves far less as the tree changes.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "gravity/gravity_test_util.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class LinearTreeEnergyTest : public ::testing::Test {};
TYPED_TEST_SUITE(LinearTreeEnergyTest, testing::Precisions);

struct Outcome {
  double worst_energy = 0, worst_virial = 0;
};

template <class Real>
Outcome run(const GravitySettings& g) {
  constexpr double dt = 1.0 / 64;
  const int steps = int(std::ceil(10 * kHenonCrossingTime / dt));
  SimulationSettings s;
  s.dt = dt;
  s.block_size = 256;
  Simulation<Real> sim(plummer<Real>(2048, 2024), s);
  sim.add_solver(std::make_unique<GravityForce<Real>>(g));
  sim.start();
  const Diagnostics d0 = diagnose(sim.particles());
  Outcome o;
  for (int step = 1; step <= steps; ++step) {
    sim.step();
    if (step % 32 != 0 && step != steps) continue;
    const Diagnostics d = diagnose(sim.particles());
    o.worst_energy = std::max(o.worst_energy, std::abs(d.total / d0.total - 1));
    o.worst_virial = std::max(o.worst_virial, std::abs(d.virial_ratio - 1));
  }
  return o;
}

TYPED_TEST(LinearTreeEnergyTest, PlummerSphereConservesEnergyAsWellAsTheBaseline) {
  using Real = TypeParam;
  GravitySettings linear;
  linear.opening = 0.5;
  linear.softening = 0.05;
  ASSERT_EQ(linear.tree, Tree::Linear);
  ASSERT_EQ(linear.multipole, Multipole::Quadrupole);
  ASSERT_EQ(linear.criterion, Criterion::Barnes);
  GravitySettings paper = linear;
  paper.tree = Tree::Paper;
  const Outcome l = run<Real>(linear);
  const Outcome p = run<Real>(paper);
  this->RecordProperty("linear_energy_error", std::to_string(l.worst_energy));
  this->RecordProperty("paper_energy_error", std::to_string(p.worst_energy));
  EXPECT_LT(l.worst_energy, 4.8e-4 + 2e-3);
  EXPECT_LE(l.worst_energy, 1.5 * p.worst_energy + 1e-4);
  EXPECT_LT(l.worst_virial, 0.1);
}

}  // namespace
}  // namespace swirl::gravity
