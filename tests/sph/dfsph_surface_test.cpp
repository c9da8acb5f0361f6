// DFSPH's non-pressure terms at the level of their passes (sph/dfsph_passes.hpp,
// SphFluid::apply_xsph and add_non_pressure) on a cubic lattice:
//  - XSPH conserves linear momentum to rounding, and damps a long shear wave
//    v_x = U sin(k y) by the continuum's first-order factor 1 − ε k² M₂/6
//    per application (M₂ = ∫ r² W dV, the kernel's second moment);
//  - surface tension conserves momentum, pulls a block's corners inward and
//    leaves its interior alone;
//  - adhesion pulls the fluid next to a wall of boundary particles towards it
//    and nothing further than h from it;
//  - Akinci's splines have their stated shape.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <vector>

#include "swirl/core/particle_kind.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/sph/kernels.hpp"
#include "swirl/sph/lattice_mass.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;

constexpr double kSpacing = 0.02, kRho0 = 1000;

struct Lattice {
  ParticleSet<double> p;
  double h = 0, side = 0;
  // More than 1.5 h from every face of the fluid block.
  bool deep(std::size_t i) const {
    for (int a = 0; a < 3; ++a)
      if (p.position[a][i] < 1.5 * h || p.position[a][i] > side - 1.5 * h) return false;
    return true;
  }
};

// A fluid lattice filling [0, side]³ (cell centres), cubic-spline mass.
Lattice lattice(double side) {
  Lattice l;
  l.side = side;
  l.h = sph::smoothing_length_for_neighbours(30, kSpacing * kSpacing * kSpacing);
  const double m = sph::lattice_mass_for_density(kSpacing, l.h, kRho0, sph::SphKernel::CubicSpline);
  std::size_t n = 0;
  for (double z = kSpacing / 2; z < side; z += kSpacing)
    for (double y = kSpacing / 2; y < side; y += kSpacing)
      for (double x = kSpacing / 2; x < side; x += kSpacing) {
        l.p.resize(n + 1);
        l.p.position.set(n, Vec3d{x, y, z});
        l.p.mass[n] = m;
        l.p.id[n] = n;
        ++n;
      }
  return l;
}

sph::SphParameters parameters(double h, double xsph, double gamma, double beta) {
  sph::SphParameters params;
  params.smoothing_length = h;
  params.rest_density = kRho0;
  params.viscosity = 0;
  params.method = sph::SphMethod::Dfsph;
  params.kernel = sph::SphKernel::CubicSpline;
  params.xsph = xsph;
  params.surface_tension = gamma;
  params.adhesion = beta;
  return params;
}

Vec3d momentum(const ParticleSet<double>& p, const Vec3Array<double>& v) {
  Vec3d s{};
  for (std::size_t i = 0; i < p.size(); ++i) s += p.mass[i] * v.get(i);
  return s;
}
double magnitude_sum(const ParticleSet<double>& p, const Vec3Array<double>& v) {
  double s = 0;
  for (std::size_t i = 0; i < p.size(); ++i) s += p.mass[i] * norm(v.get(i));
  return s;
}

TEST(Xsph, ConservesLinearMomentumToRounding) {
  Lattice l = lattice(0.2);
  sph::SphFluid<double> fluid(parameters(l.h, 0.5, 0, 0));
  spatial::ParticleOrder<double> order;  // the grid is a view of it: kept for the passes
  evaluate_alone(fluid, l.p, order, 64);
  std::uint64_t state = 12345;
  auto uniform = [&] {  // a fixed LCG: the same velocities on every machine
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) * 0x1p-53 - 0.5;
  };
  for (std::size_t i = 0; i < l.p.size(); ++i) l.p.velocity.set(i, Vec3d{uniform(), uniform(), uniform()});
  const ParticleSet<double> before = l.p;
  const Vec3d p0 = momentum(l.p, l.p.velocity);
  fluid.apply_xsph(l.p, 64);
  const Vec3d p1 = momentum(l.p, l.p.velocity);
  const double scale = magnitude_sum(before, before.velocity);
  double changed = 0;
  for (std::size_t i = 0; i < l.p.size(); ++i) changed += l.p.mass[i] * norm(l.p.velocity.get(i) - before.velocity.get(i));
  std::printf("XSPH: |Δ momentum| / Σ m|v| = %.3g, mean |Δv| / mean |v| = %.3g\n", norm(p1 - p0) / scale,
              changed / scale);
  EXPECT_LE(norm(p1 - p0), 1e-12 * scale);
  EXPECT_GT(changed, 0.1 * scale);  // the filter did act (ε = 0.5 on random velocities)
}

// M₂ = 4π ∫₀ʰ r⁴ W(r) dr of the cubic spline, by Simpson's rule.
double second_moment(double h) {
  const sph::CubicSpline<double> w(h);
  const int n = 2000;
  const double dr = h / n;
  double s = 0;
  for (int k = 0; k <= n; ++k) {
    const double r = k * dr, f = r * r * r * r * w(r);
    s += f * (k == 0 || k == n ? 1 : (k % 2 ? 4 : 2));
  }
  return 4 * std::numbers::pi * s * dr / 3;
}

TEST(Xsph, DampsALongShearWaveAtTheContinuumRate) {
  Lattice l = lattice(0.3);
  const double epsilon = 0.2;
  sph::SphFluid<double> fluid(parameters(l.h, epsilon, 0, 0));
  spatial::ParticleOrder<double> order;  // the grid is a view of it: kept for the passes
  evaluate_alone(fluid, l.p, order, 64);
  const double k = 2 * std::numbers::pi / 0.6, U = 0.1;  // λ = 0.6 m: k h ≈ 0.4
  for (std::size_t i = 0; i < l.p.size(); ++i) l.p.velocity.x[i] = U * std::sin(k * l.p.position.y[i]);
  const ParticleSet<double> before = l.p;
  fluid.apply_xsph(l.p, 64);
  // The least-squares factor Δv = f·v over the deep particles.
  double dv_v = 0, v_v = 0, sideways = 0;
  for (std::size_t i = 0; i < l.p.size(); ++i) {
    if (!l.deep(i)) continue;
    const double v = before.velocity.x[i];
    dv_v += (l.p.velocity.x[i] - v) * v;
    v_v += v * v;
    sideways = std::max({sideways, std::abs(l.p.velocity.y[i]), std::abs(l.p.velocity.z[i])});
  }
  ASSERT_GT(v_v, 0);
  const double measured = dv_v / v_v, expected = -epsilon * k * k * second_moment(l.h) / 6;
  std::printf("XSPH shear wave: factor per application %.6g, continuum first order %.6g (%.2f %%)\n", measured,
              expected, 100 * (measured / expected - 1));
  // The lattice's discrete second moment and the O((kh)⁴) term: within 5 %.
  EXPECT_NEAR(measured, expected, 0.05 * std::abs(expected));
  EXPECT_EQ(sideways, 0.0);  // a shear flow along x stays along x
}

TEST(SurfaceTension, PullsTheCornersInAndConservesMomentum) {
  Lattice l = lattice(0.24);
  sph::SphFluid<double> fluid(parameters(l.h, 0, 1.0, 0));
  spatial::ParticleOrder<double> order;  // the grid is a view of it: kept for the passes
  evaluate_alone(fluid, l.p, order, 64);
  for (int a = 0; a < 3; ++a) std::fill(l.p.acceleration[a].begin(), l.p.acceleration[a].end(), 0.0);
  fluid.add_non_pressure(l.p, 64);
  const Vec3d total = momentum(l.p, l.p.acceleration);
  const double scale = magnitude_sum(l.p, l.p.acceleration);
  ASSERT_GT(scale, 0);
  EXPECT_LE(norm(total), 1e-12 * scale);
  const Vec3d centre{l.side / 2, l.side / 2, l.side / 2};
  double corner = 0, deep = 0;
  int corners = 0;
  for (std::size_t i = 0; i < l.p.size(); ++i) {
    const Vec3d r = l.p.position.get(i) - centre, a = l.p.acceleration.get(i);
    if (l.deep(i)) deep = std::max(deep, norm(a));
    bool at_corner = true;
    for (int c = 0; c < 3; ++c) at_corner = at_corner && std::abs(r[c]) > l.side / 2 - kSpacing;
    if (!at_corner) continue;
    ++corners;
    corner = std::max(corner, norm(a));
    EXPECT_LT(dot(a, r), -0.5 * norm(a) * norm(r)) << i;  // inward, within 60°
  }
  EXPECT_EQ(corners, 8);
  std::printf("surface tension: |a| at the corners %.4g m/s², deep inside at most %.3g\n", corner, deep);
  EXPECT_LT(deep, 1e-9 * corner);  // the lattice's symmetric sums cancel inside
}

TEST(Adhesion, PullsTheFluidNextToAWallTowardsIt) {
  // A fluid lattice on a floor of boundary particles at z = −s/2 (one layer,
  // as box.walls = "particles" puts it), reaching 2h beyond the block sideways.
  Lattice l = lattice(0.2);
  const std::size_t kind = l.p.add_int_field(std::string(kKindField));
  for (double y = -0.1 + kSpacing / 2; y < 0.3; y += kSpacing)
    for (double x = -0.1 + kSpacing / 2; x < 0.3; x += kSpacing) {
      const std::size_t i = l.p.size();
      l.p.resize(i + 1);
      l.p.position.set(i, Vec3d{x, y, -kSpacing / 2});
      l.p.mass[i] = 0;  // ψ_b: the fluid computes it at its first evaluation
      l.p.id[i] = i;
      l.p.int_field(kind)[i] = static_cast<std::int32_t>(ParticleKind::Boundary);
    }
  const double beta = 2;
  sph::SphFluid<double> fluid(parameters(l.h, 0, 0, beta));
  spatial::ParticleOrder<double> order;  // the grid is a view of it: kept for the passes
  evaluate_alone(fluid, l.p, order, 64);
  for (int a = 0; a < 3; ++a) std::fill(l.p.acceleration[a].begin(), l.p.acceleration[a].end(), 0.0);
  fluid.add_non_pressure(l.p, 64);
  const auto* k = l.p.int_field(l.p.find_int_field(kKindField)).data();
  int pulled = 0;
  double strongest = 0;
  for (std::size_t i = 0; i < l.p.size(); ++i) {
    const Vec3d x = l.p.position.get(i), a = l.p.acceleration.get(i);
    if (is_boundary(k[i])) {
      EXPECT_EQ(norm(a), 0.0);
      continue;
    }
    if (x.z + kSpacing / 2 >= l.h) {  // h or more from the wall's plane
      EXPECT_EQ(norm(a), 0.0) << i;
      continue;
    }
    // Towards the floor; sideways only where the floor's sums are one-sided (none: it reaches 2h beyond).
    EXPECT_LT(a.z, 0) << i;
    EXPECT_LT(std::abs(a.x) + std::abs(a.y), 1e-9 * std::abs(a.z)) << i;
    strongest = std::max(strongest, -a.z);
    ++pulled;
  }
  // The first layer (a spacing from the wall's plane, h ≈ 1.95 spacings): 10 × 10 particles.
  EXPECT_EQ(pulled, 100);
  std::printf("adhesion (β = %g): %d fluid particles pulled, at most %.4g m/s²\n", beta, pulled, strongest);
}

TEST(AkinciSplines, HaveTheirStatedShape) {
  const double h = 0.04;
  const sph::AkinciCohesion<double> c(h);
  const sph::AkinciAdhesion<double> a(h);
  // C: continuous at h/2, negative (repulsive) near 0, positive beyond, 0 from h on.
  EXPECT_NEAR(c(0.5 * h * (1 - 1e-12)), c(0.5 * h * (1 + 1e-12)), 1e-9 * c(0.5 * h));
  EXPECT_LT(c(0.1 * h), 0);
  EXPECT_GT(c(0.4 * h), 0);
  EXPECT_EQ(c(h), 0);
  EXPECT_EQ(c(0), 0);
  EXPECT_NEAR(c(0.5 * h), 32 / (std::numbers::pi * std::pow(h, 9)) * std::pow(h, 6) / 64, 1e-12 * c(0.5 * h));
  // A: 0 up to h/2 and from h on, largest at 3h/4, where −4r²/h + 6r − 2h = h/4.
  EXPECT_EQ(a(0.5 * h), 0);
  EXPECT_EQ(a(0.3 * h), 0);
  EXPECT_EQ(a(h), 0);
  const double peak = 0.007 / std::pow(h, 3.25) * std::pow(h / 4, 0.25);
  EXPECT_NEAR(a(0.75 * h), peak, 1e-12 * peak);
  EXPECT_LT(a(0.7 * h), peak);
  EXPECT_LT(a(0.8 * h), peak);
}

}  // namespace
