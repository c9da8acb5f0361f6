// SPH with self-gravity against an analytic result (issue 16, item 8): a
// sphere of stiff, weakly compressible fluid held only by its own gravity
// settles into hydrostatic balance, where (uniform density ρ0, radius R)
//     p(r) = (2π/3)·G·ρ0²·(R² − r²).
// Scaled units (G = ρ0 = R = 1): in SI the pressure of a metre-sized drop
// would drown in rounding. The fluid is stiff (c = 10: the central pressure
// 2π/3 compresses it by 2 %), its pressure the consistent form (eq. 2.8 without
// the ½, so that p is the physical pressure) with the kernel-gradient
// correction (sph.gradient_correction), and a drag (forces.damping) removes the
// kinetic energy until it is below 1e-6 of |W|.
//
// The run uses every seam at once: two solvers and a drag in one simulation,
// one particle order for the SPH grid and the gravity tree (Morton, one sort
// per step), the guard's limits from both solvers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <vector>

#include "sph/sph_test_support.hpp"
#include "swirl/force/damping.hpp"
#include "swirl/gravity/diagnostics.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;

struct Settled {
  int steps = 0;
  double kinetic = 0, potential = 0;
  std::uint64_t sorts = 0;
  double radius = 0;                    // R from the mass: (3M / 4πρ0)^(1/3)
  std::vector<double> shell_r, shell_p;  // mean radius and pressure per shell
};

Settled settle_sphere() {
  using Real = double;
  const double s = 0.1, rho0 = 1, c = 10;
  const double h = sph::smoothing_length_for_neighbours(30, s * s * s);
  auto p = swirl::testing::lattice_fluid<Real>({-1, -1, -1}, {1, 1, 1}, s, h, rho0,
                                        [](const Vec3d& x) { return x.x * x.x + x.y * x.y + x.z * x.z <= 1.0; });
  double mass = 0;
  for (std::size_t i = 0; i < p.size(); ++i) mass += p.mass[i];
  SimulationSettings settings;  // open space: no box
  settings.dt = 0.01;
  settings.block_size = 256;
  Simulation<Real> sim(std::move(p), settings);
  sph::SphParameters fluid;
  fluid.smoothing_length = h;
  fluid.rest_density = rho0;
  fluid.sound_speed = c;
  fluid.viscosity = 0;
  fluid.pressure_form = sph::PressureForm::Consistent;
  fluid.negative_pressure = sph::NegativePressure::Zero;
  fluid.gradient_correction = true;
  sim.add_solver(std::make_unique<sph::SphFluid<Real>>(fluid));
  gravity::GravitySettings g;
  g.softening = 0.5 * s;
  g.opening = 0.4;
  sim.add_solver(std::make_unique<gravity::GravityForce<Real>>(g, gravity::SelfGravityOptions{1.0, 0.75}));
  sim.add_solver(std::make_unique<Damping<Real>>(4.0));
  sim.start();
  Settled out;
  out.radius = std::cbrt(3 * mass / (4 * std::numbers::pi * rho0));
  for (out.steps = 1; out.steps <= 4000; ++out.steps) {
    sim.step();
    if (out.steps % 25 != 0) continue;
    const auto d = gravity::diagnose(sim.particles(), settings.block_size);
    out.kinetic = d.kinetic;
    out.potential = d.potential;
    if (d.kinetic < 1e-6 * std::abs(d.potential)) break;
  }
  out.sorts = sim.order().sorts();
  // Mean pressure in shells of width 0.15 R out to 0.75 R (the surface layer,
  // where the kernel lacks neighbours, is left out: about 1.3 h).
  const auto& q = sim.particles();
  const int shells = 5;
  std::vector<double> sum_r(shells, 0), sum_p(shells, 0), count(shells, 0);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double r = std::sqrt(q.position.x[i] * q.position.x[i] + q.position.y[i] * q.position.y[i] +
                               q.position.z[i] * q.position.z[i]);
    const int k = static_cast<int>(r / (0.15 * out.radius));
    if (k >= shells) continue;
    sum_r[k] += r, sum_p[k] += q.pressure[i], count[k] += 1;
  }
  for (int k = 0; k < shells; ++k)
    if (count[k] > 0) out.shell_r.push_back(sum_r[k] / count[k]), out.shell_p.push_back(sum_p[k] / count[k]);
  return out;
}

TEST(HydrostaticSphere, SettlesToTheAnalyticPressureProfile) {
  const Settled s = settle_sphere();
  ASSERT_LT(s.kinetic, 1e-6 * std::abs(s.potential)) << "not settled after " << s.steps << " steps";
  // One order, one sort per step, for both solvers (and the first evaluation).
  EXPECT_EQ(s.sorts, std::uint64_t(s.steps) + 1);
  ASSERT_EQ(s.shell_r.size(), 5u);
  // The profile's shape: a least-squares fit p ≈ a − b·r² over the shells.
  // Its curvature b is the physics, (2π/3)·G·ρ0² (hydrostatic balance,
  // dp/dr = −ρ g(r)): held to 5 % (measured 4 %; without the gradient
  // correction 8.6 %, the spiky gradient's lattice deficit, sph/laws.hpp).
  // The shells must lie on that parabola to 2 % of the central pressure.
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < s.shell_r.size(); ++k) {
    const double x = -s.shell_r[k] * s.shell_r[k], y = s.shell_p[k];
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx), a = (sy - b * sx) / n;
  const double curvature = 2 * std::numbers::pi / 3, central = curvature * s.radius * s.radius;
  std::printf("settled after %d steps, K/|W| = %.2e, R = %.4f; fit p = %.4f - %.4f r^2 (analytic %.4f - %.4f r^2)\n"
              "  r        p        p(r)\n",
              s.steps, s.kinetic / std::abs(s.potential), s.radius, a, b, central, curvature);
  EXPECT_NEAR(b / curvature, 1.0, 0.05) << "the curvature of p(r)";
  for (std::size_t k = 0; k < s.shell_r.size(); ++k) {
    const double r = s.shell_r[k];
    const double expected = curvature * (s.radius * s.radius - r * r);
    std::printf("  %.3f    %.4f   %.4f\n", r, s.shell_p[k], expected);
    EXPECT_NEAR(s.shell_p[k], a - b * r * r, 0.02 * central) << "shell at r = " << r << " off the fitted parabola";
    // The absolute level carries one more, uniform, error: c²·δρ of the
    // density sum's bias in a settled (not lattice) packing and at the free
    // surface (measured +5.6 % of p_c: 0.1 % of ρ0 at c = 10).
    EXPECT_NEAR(s.shell_p[k], expected, 0.08 * central) << "shell at r = " << r << " (R = " << s.radius << ")";
  }
}

}  // namespace
