// The gravitational laws (gravity/pair_law.hpp) against their equations
// written out here independently: the softened pair law, and the quadrupole
// term against the exact field of point masses (on an axis in closed form,
// elsewhere the direct sum at large distance), plus the batch instantiation.
#include "swirl/gravity/pair_law.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <xsimd/xsimd.hpp>

namespace {

using namespace swirl::gravity;

struct Sums {
  double ax = 0, ay = 0, az = 0, phi = 0;
};

TEST(PairLaw, PointMassIsSoftenedNewton) {
  const double m = 2.5, eps = 0.3, d[3] = {0.4, -1.2, 0.7};
  const double R = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps * eps);
  Sums s;
  add_point(d[0], d[1], d[2], m, inverse_distance(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps * eps), s);
  EXPECT_NEAR(s.ax, m * d[0] / (R * R * R), 1e-15);
  EXPECT_NEAR(s.ay, m * d[1] / (R * R * R), 1e-15);
  EXPECT_NEAR(s.az, m * d[2] / (R * R * R), 1e-15);
  EXPECT_NEAR(s.phi, -m / R, 1e-15);
  // Zero softened distance: nothing (inv = 0), not inf/NaN.
  Sums zero;
  add_point(0.0, 0.0, 0.0, m, inverse_distance(0.0), zero);
  EXPECT_EQ(zero.ax, 0.0);
  EXPECT_EQ(zero.phi, 0.0);
}

// The traceless quadrupole Q_ab = Σ m (3 r_a r_b − r² δ_ab) of point masses
// about their centre of mass.
struct Cell {
  double m = 0, com[3] = {0, 0, 0};
  Quadrupole<double> Q{0, 0, 0, 0, 0, 0};
};

Cell cell_of(const std::vector<std::array<double, 4>>& points) {  // x, y, z, m
  Cell c;
  for (const auto& p : points) {
    c.m += p[3];
    for (int a = 0; a < 3; ++a) c.com[a] += p[3] * p[a];
  }
  for (double& x : c.com) x /= c.m;
  double q[3][3] = {};
  for (const auto& p : points) {
    const double r[3] = {p[0] - c.com[0], p[1] - c.com[1], p[2] - c.com[2]};
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) q[a][b] += p[3] * (3 * r[a] * r[b] - (a == b ? r2 : 0));
  }
  c.Q = {q[0][0], q[0][1], q[0][2], q[1][1], q[1][2], q[2][2]};
  return c;
}

Sums cell_field(const Cell& c, const double target[3], bool quadrupole) {
  const double d[3] = {c.com[0] - target[0], c.com[1] - target[1], c.com[2] - target[2]};
  const double inv = inverse_distance(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  Sums s;
  if (quadrupole)
    add_cell(d[0], d[1], d[2], c.m, c.Q, inv, s);
  else
    add_point(d[0], d[1], d[2], c.m, inv, s);
  return s;
}

Sums direct_field(const std::vector<std::array<double, 4>>& points, const double target[3]) {
  Sums s;
  for (const auto& p : points) {
    const double d[3] = {p[0] - target[0], p[1] - target[1], p[2] - target[2]};
    const double R = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    s.ax += p[3] * d[0] / (R * R * R);
    s.ay += p[3] * d[1] / (R * R * R);
    s.az += p[3] * d[2] / (R * R * R);
    s.phi -= p[3] / R;
  }
  return s;
}

// Two masses m at ±s on the z axis, seen from z on the axis:
//   φ = −m/(z − s) − m/(z + s) = −2m/z − 2m s²/z³ − O(s⁴/z⁵),
// the second term the quadrupole's (Q_zz = 4 m s²): φ_quad = −½ z² Q_zz / z⁵;
// a_z = −∂φ/∂z = −2m/z² − 6 m s²/z⁴.
TEST(PairLaw, QuadrupoleOfTwoMassesOnTheAxis) {
  const double m = 1.5, s = 0.2, z = 3.0;
  const Cell c = cell_of({{0, 0, s, m}, {0, 0, -s, m}});
  EXPECT_NEAR(c.Q.zz, 4 * m * s * s, 1e-15);
  const double target[3] = {0, 0, z};
  const Sums got = cell_field(c, target, true);
  EXPECT_NEAR(got.phi, -2 * m / z - 2 * m * s * s / (z * z * z), 1e-14);
  EXPECT_NEAR(got.az, -2 * m / (z * z) - 6 * m * s * s / (z * z * z * z), 1e-14);
  EXPECT_NEAR(got.ax, 0.0, 1e-15);
  EXPECT_NEAR(got.ay, 0.0, 1e-15);
}

// Random masses in a unit box seen from far away, summed over directions (in
// one direction the quadrupole's dᵀQd may vanish by chance): monopole +
// quadrupole converge to the direct sum one order faster than the monopole
// (the dipole vanishes about the centre of mass): the error in φ falls as
// 1/R⁴ against 1/R³. A wrong sign or factor in the quadrupole term leaves an
// error ~ 1/R³, larger than the monopole's or as large, and fails.
TEST(PairLaw, QuadrupoleApproachesTheDirectSumAtLargeDistance) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<std::array<double, 4>> points;
  for (int k = 0; k < 12; ++k) points.push_back({u(rng), u(rng), u(rng), 1 + u(rng)});
  const Cell c = cell_of(points);
  std::vector<std::array<double, 3>> directions;
  for (int k = 0; k < 32; ++k) {
    std::array<double, 3> v{u(rng), u(rng), u(rng)};
    const double n = std::hypot(v[0], v[1], v[2]);
    for (double& x : v) x /= n;
    directions.push_back(v);
  }
  double previous = 0;
  for (double R : {10.0, 20.0, 40.0}) {
    double phi_quad = 0, phi_mono = 0, acc_quad = 0, acc_mono = 0;
    for (const auto& dir : directions) {
      const double target[3] = {c.com[0] + R * dir[0], c.com[1] + R * dir[1], c.com[2] + R * dir[2]};
      const Sums exact = direct_field(points, target), quad = cell_field(c, target, true),
                 mono = cell_field(c, target, false);
      phi_quad += std::abs(quad.phi - exact.phi);
      phi_mono += std::abs(mono.phi - exact.phi);
      acc_quad += std::hypot(quad.ax - exact.ax, quad.ay - exact.ay, quad.az - exact.az);
      acc_mono += std::hypot(mono.ax - exact.ax, mono.ay - exact.ay, mono.az - exact.az);
    }
    EXPECT_LT(phi_quad, 0.2 * phi_mono) << R;
    EXPECT_LT(acc_quad, 0.3 * acc_mono) << R;
    if (previous > 0) {
      EXPECT_LT(phi_quad, previous / 12) << R;  // 1/16 per doubling (1/8 would be a leftover 1/R³)
    }
    previous = phi_quad;
  }
}

// With Q = 0 the cell law is the point-mass law, bit for bit (the merged
// radial coefficient adds exact zeros).
TEST(PairLaw, CellWithoutQuadrupoleIsThePointLaw) {
  const double d[3] = {0.3, 0.9, -1.4}, m = 0.7, eps2 = 0.01;
  const double inv = inverse_distance(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2);
  Sums a, b;
  add_point(d[0], d[1], d[2], m, inv, a);
  add_cell(d[0], d[1], d[2], m, Quadrupole<double>{0, 0, 0, 0, 0, 0}, inv, b);
  EXPECT_EQ(a.ax, b.ax);
  EXPECT_EQ(a.ay, b.ay);
  EXPECT_EQ(a.az, b.az);
  EXPECT_EQ(a.phi, b.phi);
}

// The SIMD kernels instantiate add_cell with batches: lane by lane it equals
// the scalar instantiation to rounding.
TEST(PairLaw, BatchesEvaluateTheSameCellLaw) {
  using B = xsimd::batch<double>;
  constexpr std::size_t W = B::size;
  alignas(64) double dx[W], dy[W], dz[W], m[W], inv[W];
  for (std::size_t k = 0; k < W; ++k) {
    dx[k] = 1.0 + 0.3 * double(k);
    dy[k] = -0.5 + 0.1 * double(k);
    dz[k] = 2.0 - 0.2 * double(k);
    m[k] = 1.0 + 0.05 * double(k);
    inv[k] = 1 / std::sqrt(dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]);
  }
  const Quadrupole<double> q{0.3, -0.1, 0.05, 0.2, 0.07, -0.5};
  const Quadrupole<B> Q{B(q.xx), B(q.xy), B(q.xz), B(q.yy), B(q.yz), B(q.zz)};
  struct BatchSums {
    B ax = B(0.0), ay = B(0.0), az = B(0.0), phi = B(0.0);
  } bs;
  add_cell(B::load_aligned(dx), B::load_aligned(dy), B::load_aligned(dz), B::load_aligned(m), Q, B::load_aligned(inv),
           bs);
  alignas(64) double ax[W], phi[W];
  bs.ax.store_aligned(ax);
  bs.phi.store_aligned(phi);
  for (std::size_t k = 0; k < W; ++k) {
    Sums s;
    add_cell(dx[k], dy[k], dz[k], m[k], q, inv[k], s);
    EXPECT_NEAR(ax[k], s.ax, 1e-14 * std::abs(s.ax)) << k;
    EXPECT_NEAR(phi[k], s.phi, 1e-14 * std::abs(s.phi)) << k;
  }
}

}  // namespace
