// The stepper's drift–force–kick map is leapfrog kick-drift-kick; on a
// harmonic oscillator x'' = −ω²x with step h it conserves exactly the modified
// energy H = v² + ω²x²(1 − (ωh)²/4) at full steps (VALIDATION.md), while the
// ordinary energy v² + ω²x² oscillates with relative amplitude ≈ (ωh)²/4.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "gravity/gravity_test_util.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"

namespace swirl::gravity {
namespace {

// a = −ω²·x on every axis.
template <class Real>
class Spring final : public Solver<Real> {
 public:
  explicit Spring(Real omega) : omega2_(omega * omega) {}
  std::string_view name() const override { return "spring"; }
  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
    parallel::for_blocks("spring", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (int a = 0; a < 3; ++a)
        for (std::size_t i = b; i < e; ++i) p.acceleration[a][i] += -omega2_ * p.position[a][i];
    });
  }

 private:
  Real omega2_;
};

template <class Real>
class LeapfrogTest : public ::testing::Test {};
TYPED_TEST_SUITE(LeapfrogTest, testing::Precisions);

TYPED_TEST(LeapfrogTest, ConservesTheModifiedEnergyOfAHarmonicOscillator) {
  using Real = TypeParam;
  constexpr double omega = 1.5, h = 0.2;  // ωh = 0.3: (ωh)²/4 = 0.0225
  constexpr int steps = 1000;
  ParticleSet<Real> p(4);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.position.set(i, Vec3<double>{1.0 + double(i), -0.5 * double(i), 0.25}.cast<Real>());
    p.velocity.set(i, Vec3<double>{0.3, 1.0 - double(i), -2.0}.cast<Real>());
    p.mass[i] = 1;
    p.id[i] = i;
  }
  // Four particles need no threads (and a busy machine makes thousands of tiny parallel loops slow).
  const int saved = parallel::thread_count();
  parallel::set_thread_count(1);
  SimulationSettings s;
  s.dt = h;
  Simulation<Real> sim(std::move(p), s);
  sim.add_solver(std::make_unique<Spring<Real>>(Real(omega)));
  sim.start();
  const double w2 = omega * omega, shrink = 1 - w2 * h * h / 4;
  // Per particle: H and E = v² + ω²x² summed over the axes.
  const auto energies = [&](std::size_t i, double factor) {
    const auto& q = sim.particles();
    double e = 0;
    for (int a = 0; a < 3; ++a) e += std::pow(double(q.velocity[a][i]), 2) + w2 * factor * std::pow(double(q.position[a][i]), 2);
    return e;
  };
  std::vector<double> h0, e0;
  for (std::size_t i = 0; i < 4; ++i) {
    h0.push_back(energies(i, shrink));
    e0.push_back(energies(i, 1));
  }
  double worst_h = 0, worst_e = 0;
  for (int step = 0; step < steps; ++step) {
    sim.step();
    for (std::size_t i = 0; i < 4; ++i) {
      worst_h = std::max(worst_h, std::abs(energies(i, shrink) / h0[i] - 1));
      worst_e = std::max(worst_e, std::abs(energies(i, 1) / e0[i] - 1));
    }
  }
  parallel::set_thread_count(saved);
  // H is conserved up to rounding: an ulp or so per step, of random sign,
  // accumulating like a random walk (measured: 0.8·√steps·ε in both precisions).
  EXPECT_LT(worst_h, 4.0 * std::sqrt(double(steps)) * std::numeric_limits<Real>::epsilon());
  // The ordinary energy is not: it swings by ~(ωh)²/4 — which the bound above would catch.
  EXPECT_GT(worst_e, 0.5 * w2 * h * h / 4);
  EXPECT_LT(worst_e, 2.0 * w2 * h * h / 4 / shrink);
}

}  // namespace
}  // namespace swirl::gravity
