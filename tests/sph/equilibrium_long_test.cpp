// Fluids at rest: a hydrostatic column and a free drop (long: skipped under sanitizers).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "sph_test_support.hpp"

namespace {

using namespace swirl;

template <class Real>
class SphEquilibrium : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SphEquilibrium, Precisions);

// Least-squares slope of y(x).
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t k = 0; k < x.size(); ++k) { mx += x[k]; my += y[k]; }
  mx /= double(x.size());
  my /= double(y.size());
  double sxy = 0, sxx = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    sxy += (x[k] - mx) * (y[k] - my);
    sxx += (x[k] - mx) * (x[k] - mx);
  }
  return sxy / sxx;
}

// The slope of p(z) over particles at least 2h from the floor, the surface and
// the side walls (kernel truncation biases all of them).
template <class Real>
double pressure_gradient(const ParticleSet<Real>& p, double h, double width) {
  double top = 0;
  for (std::size_t i = 0; i < p.size(); ++i) top = std::max(top, double(p.position.z[i]));
  std::vector<double> z, pressure;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.position.x[i], y = p.position.y[i], zi = p.position.z[i];
    if (zi < 2 * h || zi > top - 2 * h || x < 2 * h || x > width - 2 * h || y < 2 * h || y > width - 2 * h) continue;
    z.push_back(zi);
    pressure.push_back(p.pressure[i]);
  }
  EXPECT_GT(z.size(), 300u);
  return slope(z, pressure);
}

// A column of depth H = 0.3 m in a 0.18 m × 0.18 m box settles; c = 20 m/s ≥
// 10·sqrt(g·H) ≈ 17.2 m/s. The per-particle pressure is noisy (c²·δρ with δρ of
// a few %, against ρ0·g·H), so dp/dz is averaged over 26 samples in the
// second half of the run.
//
// Expected: the discrete pressure force on particles of this spacing applies
// κ·∇p, κ measured on a stretched lattice (0.954 at h = 2.1·s for the consistent
// form, exactly half that for eq. 2.8: see ThePressureForceOfEquation28IsHalfTheGradient).
// Equilibrium needs κ·dp/dz = ρ0·g, so with eq. 2.8 (PressureForm::Thesis)
// dp/dz ≈ 2·ρ0·g/0.954: the fluid's physical pressure is p/2, and it must
// settle within 10 % of the κ-corrected expectation (measured 1.02–1.07). The
// consistent form, twice as stiff at the same c, settles noisier (measured
// 1.02–1.12 after the correction); its gradient is checked exactly on the
// stretched lattice instead.
double settled_gradient_ratio(sph::PressureForm form, auto real_tag) {
  using Real = decltype(real_tag);
  const double s = 0.012, h = 2.1 * s, rho0 = 1000, g = 9.81, H = 0.3, c = 20, width = 0.18;
  SimulationSettings settings;
  settings.dt = 2.5e-4;  // CFL: 0.4·h/c = 5e-4
  settings.block_size = 128;
  settings.box = boundary::BoxCollision<double>{{{0, 0, 0}, {width, width, 0.5}}, 0.0};
  Simulation<Real> sim(swirl::testing::lattice_fluid<Real>({0, 0, 0}, {width, width, H}, s, h, rho0), settings);
  sph::SphParameters params;
  params.smoothing_length = h;
  params.rest_density = rho0;
  params.sound_speed = c;
  params.viscosity = 5.0;  // damps the settling
  params.pressure_form = form;
  sim.add_solver(std::make_unique<sph::SphFluid<Real>>(params));
  sim.add_solver(std::make_unique<UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-g)}));
  sim.start();
  double sum = 0;
  int samples = 0;
  for (int k = 1; k <= 4000; ++k) {
    sim.step();
    if (k >= 1500 && k % 100 == 0) {
      sum += -pressure_gradient(sim.particles(), h, width) / (rho0 * g);
      ++samples;
    }
  }
  return sum / samples;
}

TYPED_TEST(SphEquilibrium, HydrostaticColumnThesisFormHasPhysicalPressureGradientRho0G) {
  const double kappa = swirl::testing::pressure_acceleration_ratio<TypeParam>(sph::PressureForm::Thesis);
  const double ratio = settled_gradient_ratio(sph::PressureForm::Thesis, TypeParam{});
  EXPECT_NEAR(ratio * kappa, 1.0, 0.10) << "dp/dz = " << ratio << " rho0 g, kappa = " << kappa;
}


// A sphere of fluid at rest, no gravity, no walls in reach, for 0.5 s.
struct DropResult {
  double max_momentum = 0;        // largest |Σ m v| component seen, kg·m/s
  double momentum_scale = 0;      // Σ m |v| at that time
  double mean_density_error = 0;  // mean |ρ − ρ0|/ρ0 at the end, over particles ≥ 2h inside
  double radius_change = 0;       // (max radius at the end) / (at the start) − 1
};

template <class Real>
DropResult run_drop(sph::NegativePressure rule) {
  const double s = 0.01, h = 2.1 * s, rho0 = 1000, R = 0.06;
  const Vec3d centre{0.1, 0.1, 0.1};
  auto keep = [&](const Vec3d& x) { const Vec3d d = x - centre; return dot(d, d) < R * R; };
  SimulationSettings settings;
  settings.dt = 2.5e-4;
  settings.block_size = 128;
  Simulation<Real> sim(swirl::testing::lattice_fluid<Real>({0, 0, 0}, {0.2, 0.2, 0.2}, s, h, rho0, keep), settings);
  sph::SphParameters params;
  params.smoothing_length = h;
  params.rest_density = rho0;
  params.sound_speed = 10;
  params.viscosity = 0.5;
  params.negative_pressure = rule;
  sim.add_solver(std::make_unique<sph::SphFluid<Real>>(params));
  sim.start();
  auto radius = [&] {
    double r = 0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      r = std::max(r, norm(sim.particles().position.get(i).template cast<double>() - centre));
    return r;
  };
  const double r0 = radius();
  DropResult out;
  for (int k = 1; k <= 2000; ++k) {
    sim.step();
    if (k % 100 != 0) continue;
    const auto& p = sim.particles();
    double momentum[3] = {0, 0, 0}, scale = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int a = 0; a < 3; ++a) {
        momentum[a] += double(p.mass[i]) * double(p.velocity[a][i]);
        scale += double(p.mass[i]) * std::abs(double(p.velocity[a][i]));
      }
    for (double m : momentum)
      if (std::abs(m) > out.max_momentum) out.max_momentum = std::abs(m), out.momentum_scale = scale;
  }
  const auto& p = sim.particles();
  std::size_t inside = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (norm(p.position.get(i).template cast<double>() - centre) > R - 2 * h) continue;
    out.mean_density_error += std::abs(double(p.density[i]) - rho0) / rho0;
    ++inside;
  }
  out.mean_density_error = inside ? out.mean_density_error / double(inside) : 1.0;
  out.radius_change = radius() / r0 - 1;
  return out;
}

// Pair forces cancel, so the momentum of a free drop stays at round-off of the
// per-particle momenta, whatever the drop does.
TYPED_TEST(SphEquilibrium, DropKeepsZeroMomentum) {
  const auto r = run_drop<TypeParam>(sph::NegativePressure::Keep);
  const double eps = std::is_same_v<TypeParam, float> ? 1e-6 : 1e-14;
  EXPECT_LE(r.max_momentum, 100 * eps * r.momentum_scale) << r.max_momentum << " of " << r.momentum_scale;
}

// With the thesis's equation of state the drop's surface is under tension and
// the drop clumps (see sph_fluid.hpp); without tension a lattice drop at rest
// density stays exactly as it is: at rest, its density ρ0 inside, its shape.
TYPED_TEST(SphEquilibrium, DropWithoutTensionStaysAtRestWithDensityRho0) {
  const auto r = run_drop<TypeParam>(sph::NegativePressure::Zero);
  const double tol = std::is_same_v<TypeParam, float> ? 1e-5 : 1e-12;
  EXPECT_LT(r.mean_density_error, tol);
  EXPECT_LT(std::abs(r.radius_change), 1e-4);
  EXPECT_LE(r.max_momentum, 1e-9);
}

}  // namespace
