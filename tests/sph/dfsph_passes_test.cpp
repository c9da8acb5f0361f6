// DFSPH's passes (sph/dfsph_passes.hpp) on a cubic lattice, where their
// continuum values are known: ρ = ρ0 inside (the fluid block's mass),
// Σ_j m_j ∇W_ij = 0 and so α = the lattice factor, Dρ/Dt = −ρ0 ∇·v for a
// linear velocity field, and a uniform κ exerts no force inside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "swirl/force/solver.hpp"
#include "swirl/sph/lattice_mass.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;

struct Lattice {
  ParticleSet<double> p;
  double s = 0.02, h = 0, rho0 = 1000, side = 0.3;
  bool deep(std::size_t i) const {
    for (int a = 0; a < 3; ++a)
      if (p.position[a][i] < 1.5 * h || p.position[a][i] > side - 1.5 * h) return false;
    return true;
  }
};

Lattice lattice(sph::SphKernel kernel) {
  Lattice l;
  l.h = sph::smoothing_length_for_neighbours(30, l.s * l.s * l.s);
  const double m = sph::lattice_mass_for_density(l.s, l.h, l.rho0, kernel);
  std::size_t n = 0;
  for (double z = l.s / 2; z < l.side; z += l.s)
    for (double y = l.s / 2; y < l.side; y += l.s)
      for (double x = l.s / 2; x < l.side; x += l.s) {
        l.p.resize(n + 1);
        l.p.position.set(n, Vec3d{x, y, z});
        l.p.mass[n] = m;
        l.p.id[n] = n;
        ++n;
      }
  return l;
}

sph::SphParameters dfsph_parameters(const Lattice& l, sph::SphKernel kernel) {
  sph::SphParameters params;
  params.smoothing_length = l.h;
  params.rest_density = l.rho0;
  params.viscosity = 0;
  params.method = sph::SphMethod::Dfsph;
  params.kernel = kernel;
  return params;
}

class DfsphPasses : public ::testing::TestWithParam<sph::SphKernel> {};

TEST_P(DfsphPasses, MatchTheirContinuumValuesInsideALattice) {
  const sph::SphKernel kernel = GetParam();
  Lattice l = lattice(kernel);
  sph::SphFluid<double> fluid(dfsph_parameters(l, kernel));
  spatial::ParticleOrder<double> order;
  evaluate_alone(fluid, l.p, order, 256);
  const std::size_t n = l.p.size();
  const double m = l.p.mass[0];
  // dfsph_lattice_factor takes ρ = m/s³, which the fluid block's mass makes
  // 0.1 % less than the summed ρ0; the factor is ρ over the same denominator.
  const double lattice_alpha =
      sph::dfsph_lattice_factor(fluid.dfsph_kernel(), m, l.s) * l.rho0 / (m / (l.s * l.s * l.s));
  // A linear velocity field v = (ε x, 0, 0): ∇·v = ε.
  const double eps = 0.5;
  for (std::size_t i = 0; i < n; ++i) l.p.velocity.x[i] = eps * l.p.position.x[i];
  std::vector<double> change(n);
  fluid.density_change(l.p, change.data(), 256);
  int deep = 0;
  double worst = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!l.deep(i)) continue;
    ++deep;
    worst = std::max(worst, std::abs(change[i] / (-l.rho0 * eps) - 1));
    EXPECT_NEAR(l.p.density[i], l.rho0, 1e-9 * l.rho0) << i;
    // α of an interior particle is the lattice's (the first sum of its denominator vanishes).
    EXPECT_NEAR(fluid.factor()[i], lattice_alpha, 1e-6 * lattice_alpha) << i;
    // Dρ/Dt = −ρ0 ε, to the lattice's discretisation error of the kernel's first moment (measured:
    // 1.5 % with the cubic spline, 5.4 % with the thesis's pair, whose gradient is not its W's).
    EXPECT_NEAR(change[i], -l.rho0 * eps, (kernel == sph::SphKernel::CubicSpline ? 0.02 : 0.07) * l.rho0 * eps) << i;
  }
  EXPECT_GT(deep, 100);
  std::printf("Drho/Dt against -rho0 div v: largest relative deviation %.4f\n", worst);
  // A uniform κ: no velocity change inside (Σ_j m_j ∇W_ij = 0); at the
  // surface the one-sided sums push outward (along the outward normal).
  for (std::size_t i = 0; i < n; ++i) l.p.velocity.x[i] = 0;
  const std::vector<double> k(n, 5.0 / l.rho0);
  fluid.pressure_velocity(l.p, k.data(), 1e-3, 256);
  for (std::size_t i = 0; i < n; ++i) {
    const double speed = std::abs(l.p.velocity.x[i]) + std::abs(l.p.velocity.y[i]) + std::abs(l.p.velocity.z[i]);
    if (l.deep(i)) {
      EXPECT_LT(speed, 1e-12) << i;
    }
    if (l.p.position.x[i] < l.s) {
      EXPECT_LT(l.p.velocity.x[i], 0) << i;  // the low-x face moves to −x
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Kernels, DfsphPasses,
                         ::testing::Values(sph::SphKernel::CubicSpline, sph::SphKernel::Thesis));

}  // namespace
