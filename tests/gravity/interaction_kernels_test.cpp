// The interaction kernels: the SIMD path of every usable instruction set
// against the scalar path to round-off, and the scalar path against the pair
// law, a direct sum over point masses and −∇φ by finite differences.
#include "swirl/gravity/interaction_kernels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "swirl/core/simd_dispatch.hpp"
#include "swirl/gravity/pair_law.hpp"

namespace swirl::gravity {
namespace {

template <class Real>
class InteractionKernels : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(InteractionKernels, Precisions);

std::vector<simd::Isa> usable_isas() {
  std::vector<simd::Isa> isas;
  for (simd::Isa isa : simd::kCompiledIsas)
    if (simd::usable(isa)) isas.push_back(isa);
  return isas;
}

// Sources as owned arrays (exact sizes, so that ASan sees any read past n).
template <class Real>
struct Sources {
  std::vector<Real> x, y, z, m, qxx, qxy, qxz, qyy, qyz;
  std::size_t size() const { return x.size(); }
  SourceParticles<Real> particles(std::size_t self_offset = SourceParticles<Real>::npos) const {
    return {x.data(), y.data(), z.data(), m.data(), size(), self_offset};
  }
  SourceCells<Real> cells() const {
    return {x.data(), y.data(), z.data(), m.data(), qxx.data(), qxy.data(), qxz.data(), qyy.data(), qyz.data(), size()};
  }
};

template <class Real>
struct Group {
  std::vector<Real> x, y, z, ax, ay, az, phi;
  std::size_t size() const { return x.size(); }
  Targets<Real> targets() { return {x.data(), y.data(), z.data(), ax.data(), ay.data(), az.data(), phi.data(), size()}; }
};

// n sources in the cube [c − half, c + half]³ with masses in [0.5, 1.5] and
// quadrupoles of size ~ m · (cell side)².
template <class Real>
Sources<Real> random_sources(std::size_t n, std::mt19937& rng, double half = 1, double c = 0, double cell_side = 0.1) {
  std::uniform_real_distribution<double> u(-1, 1);
  Sources<Real> s;
  for (std::size_t j = 0; j < n; ++j) {
    s.x.push_back(Real(c + half * u(rng)));
    s.y.push_back(Real(c + half * u(rng)));
    s.z.push_back(Real(c + half * u(rng)));
    const double m = 1 + 0.5 * u(rng);
    s.m.push_back(Real(m));
    const double q = m * cell_side * cell_side;
    for (auto* a : {&s.qxx, &s.qxy, &s.qxz, &s.qyy, &s.qyz}) a->push_back(Real(q * u(rng)));
  }
  return s;
}

// Targets in [−half, half]³ whose sums start at nonzero values (the kernels add).
template <class Real>
Group<Real> random_group(std::size_t n, std::mt19937& rng, double half = 1) {
  std::uniform_real_distribution<double> u(-1, 1);
  Group<Real> g;
  for (std::size_t i = 0; i < n; ++i) {
    g.x.push_back(Real(half * u(rng)));
    g.y.push_back(Real(half * u(rng)));
    g.z.push_back(Real(half * u(rng)));
    for (auto* a : {&g.ax, &g.ay, &g.az, &g.phi}) a->push_back(Real(u(rng)));
  }
  return g;
}

// The targets of the group are sources [offset, offset + n) of s.
template <class Real>
Group<Real> group_of(const Sources<Real>& s, std::size_t offset, std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Group<Real> g;
  for (std::size_t i = 0; i < n; ++i) {
    g.x.push_back(s.x[offset + i]);
    g.y.push_back(s.y[offset + i]);
    g.z.push_back(s.z[offset + i]);
    for (auto* a : {&g.ax, &g.ay, &g.az, &g.phi}) a->push_back(Real(u(rng)));
  }
  return g;
}

// Per target, the sum of the magnitudes of the terms (and of the start
// values): the scale against which round-off is measured. |quadrupole terms|
// ≤ 3.5 |Q| / R⁴ (acceleration) and ½ |Q| / R³ (potential), |Q| Frobenius.
struct Scale {
  std::vector<double> accel, potential;
};

template <class Real>
Scale term_scale(const Sources<Real>& s, const Group<Real>& g, double eps2, bool quadrupole) {
  Scale sc{std::vector<double>(g.size()), std::vector<double>(g.size())};
  for (std::size_t i = 0; i < g.size(); ++i) {
    double a = std::abs(double(g.ax[i])) + std::abs(double(g.ay[i])) + std::abs(double(g.az[i]));
    double p = std::abs(double(g.phi[i]));
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double dx = double(s.x[j]) - double(g.x[i]), dy = double(s.y[j]) - double(g.y[i]),
                   dz = double(s.z[j]) - double(g.z[i]);
      const double r2 = dx * dx + dy * dy + dz * dz + eps2;
      if (r2 == 0) continue;
      const double r = std::sqrt(r2);
      a += double(s.m[j]) / r2;
      p += double(s.m[j]) / r;
      if (quadrupole) {
        const double qxx = s.qxx[j], qxy = s.qxy[j], qxz = s.qxz[j], qyy = s.qyy[j], qyz = s.qyz[j];
        const double qzz = -(qxx + qyy);
        const double q = std::sqrt(qxx * qxx + qyy * qyy + qzz * qzz + 2 * (qxy * qxy + qxz * qxz + qyz * qyz));
        a += 3.5 * q / (r2 * r2);
        p += 0.5 * q / (r2 * r);
      }
    }
    sc.accel[i] = a;
    sc.potential[i] = p;
  }
  return sc;
}

// Round-off allowed relative to the scale: float pays the rsqrt + Newton step
// (~2⁻²²) and sums in float; double only its sums.
template <class Real>
constexpr double kTolerance = std::is_same_v<Real, float> ? 5e-6 : 1e-14;

template <class Real>
void expect_close(const Group<Real>& a, const Group<Real>& b, const Scale& sc, double tol, const std::string& what) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double ta = tol * sc.accel[i], tp = tol * sc.potential[i];
    ASSERT_NEAR(double(a.ax[i]), double(b.ax[i]), ta) << what << ", target " << i;
    ASSERT_NEAR(double(a.ay[i]), double(b.ay[i]), ta) << what << ", target " << i;
    ASSERT_NEAR(double(a.az[i]), double(b.az[i]), ta) << what << ", target " << i;
    ASSERT_NEAR(double(a.phi[i]), double(b.phi[i]), tp) << what << ", target " << i;
  }
}

template <class Real>
void expect_finite(const Group<Real>& g, const std::string& what) {
  for (std::size_t i = 0; i < g.size(); ++i)
    ASSERT_TRUE(std::isfinite(g.ax[i]) && std::isfinite(g.ay[i]) && std::isfinite(g.az[i]) && std::isfinite(g.phi[i]))
        << what << ", target " << i;
}

enum class Kind { particles, monopole, quadrupole };

std::string describe(Kind kind, simd::Isa isa, std::size_t ns, std::size_t nt) {
  const char* k = kind == Kind::particles ? "particles" : kind == Kind::monopole ? "monopole" : "quadrupole";
  return std::string(k) + " " + std::string(simd::isa_name(isa)) + " sources " + std::to_string(ns) + " targets " +
         std::to_string(nt);
}

template <class Real>
void apply(Kind kind, const Sources<Real>& s, Group<Real>& g, Real eps2, KernelPath path,
           std::size_t self_offset = SourceParticles<Real>::npos) {
  if (kind == Kind::particles)
    add_particle_field(s.particles(self_offset), g.targets(), eps2, path);
  else
    add_cell_field(s.cells(), g.targets(), eps2, kind == Kind::quadrupole, path);
}

// The SIMD path of every usable instruction set against the scalar path.
template <class Real>
void check_simd_against_scalar(Kind kind, const Sources<Real>& s, const Group<Real>& g, Real eps2,
                               std::size_t self_offset = SourceParticles<Real>::npos) {
  Group<Real> scalar = g;
  apply(kind, s, scalar, eps2, KernelPath::Scalar, self_offset);
  expect_finite(scalar, "scalar");
  const Scale sc = term_scale(s, g, double(eps2), kind == Kind::quadrupole);
  for (simd::Isa isa : usable_isas()) {
    simd::ScopedIsa scope(isa);
    Group<Real> fast = g;
    apply(kind, s, fast, eps2, KernelPath::Simd, self_offset);
    const std::string what = describe(kind, isa, s.size(), g.size());
    expect_finite(fast, what);
    expect_close(fast, scalar, sc, kTolerance<Real>, what);
  }
}

constexpr Kind kKinds[] = {Kind::particles, Kind::monopole, Kind::quadrupole};

TYPED_TEST(InteractionKernels, SimdMatchesScalarOnRandomInputs) {
  using Real = TypeParam;
  std::mt19937 rng(11);
  for (std::size_t ns : {1u, 2u, 7u, 64u, 301u})
    for (std::size_t nt : {1u, 16u, 37u, 64u}) {
      const Sources<Real> s = random_sources<Real>(ns, rng, 1, 0, 0.2);
      const Group<Real> g = random_group<Real>(nt, rng, 0.5);
      for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, Real(1e-4));
    }
}

TYPED_TEST(InteractionKernels, TailsOfEveryLength) {
  using Real = TypeParam;
  // 2 · 16 + 1: every tail of every batch width (≤ 16 lanes) and then some.
  constexpr std::size_t kMax = 2 * 16 + 1;
  std::mt19937 rng(12);
  for (std::size_t nt = 0; nt <= kMax; ++nt) {
    const Sources<Real> s = random_sources<Real>(nt + 3, rng);
    const Group<Real> g = random_group<Real>(nt, rng);
    for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, Real(1e-3));
  }
  for (std::size_t ns = 0; ns <= kMax; ++ns) {
    const Sources<Real> s = random_sources<Real>(ns, rng);
    const Group<Real> g = random_group<Real>(19, rng);
    for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, Real(1e-3));
  }
  // Long lists: the last targets go sources-across (every source tail too).
  for (std::size_t nt = 0; nt <= kMax; ++nt)
    for (std::size_t ns : {150u, 160u, 175u}) {
      const Sources<Real> s = random_sources<Real>(ns, rng);
      const Group<Real> g = random_group<Real>(nt, rng);
      for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, Real(1e-3));
      for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, Real(0));
    }
}

TYPED_TEST(InteractionKernels, SelfOffsetSkipsTheTargetsOwnPairs) {
  using Real = TypeParam;
  std::mt19937 rng(13);
  for (std::size_t nt = 1; nt <= 2 * 16 + 1; ++nt)
    for (std::size_t before : {0u, 1u, 5u, 40u, 100u})
      for (std::size_t after : {0u, 3u, 17u, 60u}) {
        const Sources<Real> s = random_sources<Real>(before + nt + after, rng);
        const Group<Real> g = group_of(s, before, nt, rng);
        for (Real eps2 : {Real(1e-3), Real(0)}) {
          check_simd_against_scalar(Kind::particles, s, g, eps2, before);
          // The scalar path against the pair law, self pairs left out by hand.
          Group<Real> got = g;
          apply(Kind::particles, s, got, eps2, KernelPath::Scalar, before);
          const Scale sc = term_scale(s, g, double(eps2), false);
          for (std::size_t i = 0; i < nt; ++i) {
            Accumulator<Real> acc;
            for (std::size_t j = 0; j < s.size(); ++j)
              if (j != before + i) acc.add(s.x[j] - g.x[i], s.y[j] - g.y[i], s.z[j] - g.z[i], s.m[j], eps2);
            const double tol = 4 * std::numeric_limits<Real>::epsilon();
            ASSERT_NEAR(double(got.ax[i]), double(g.ax[i] + acc.ax), tol * sc.accel[i]);
            ASSERT_NEAR(double(got.ay[i]), double(g.ay[i] + acc.ay), tol * sc.accel[i]);
            ASSERT_NEAR(double(got.az[i]), double(g.az[i] + acc.az), tol * sc.accel[i]);
            ASSERT_NEAR(double(got.phi[i]), double(g.phi[i] + acc.phi), tol * sc.potential[i]);
          }
        }
      }
}

TYPED_TEST(InteractionKernels, SelfPairWouldCountWithoutSelfOffset) {
  // The test above can fail: without self_offset a softened self pair adds −m/ε to φ.
  using Real = TypeParam;
  std::mt19937 rng(14);
  const Sources<Real> s = random_sources<Real>(9, rng);
  const Group<Real> g = group_of(s, 2, 5, rng);
  const Real eps = Real(0.1);
  for (KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
    Group<Real> with = g, without = g;
    apply(Kind::particles, s, with, eps * eps, path, 2);
    apply(Kind::particles, s, without, eps * eps, path);
    for (std::size_t i = 0; i < g.size(); ++i)
      EXPECT_NEAR(double(without.phi[i] - with.phi[i]), -double(s.m[2 + i]) / double(eps), 1e-4);
  }
}

TYPED_TEST(InteractionKernels, ZeroSeparationWithSoftening) {
  using Real = TypeParam;
  std::mt19937 rng(15);
  // Sources on top of the targets (no self_offset: they count), and others.
  Sources<Real> s = random_sources<Real>(40, rng);
  Group<Real> g = group_of(s, 3, 21, rng);
  const Real eps = Real(0.05);
  for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, eps * eps);
  // One source exactly on one target: no acceleration, φ = −m/ε (and the
  // quadrupole term vanishes: rᵀQr = 0 and Qr = 0 at r = 0).
  Sources<Real> one = random_sources<Real>(1, rng);
  Group<Real> t = random_group<Real>(1, rng);
  one.x[0] = t.x[0];
  one.y[0] = t.y[0];
  one.z[0] = t.z[0];
  for (Kind kind : kKinds)
    for (KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
      Group<Real> got = t;
      apply(kind, one, got, eps * eps, path);
      EXPECT_EQ(got.ax[0], t.ax[0]);
      EXPECT_EQ(got.ay[0], t.ay[0]);
      EXPECT_EQ(got.az[0], t.az[0]);
      EXPECT_NEAR(double(got.phi[0] - t.phi[0]), -double(one.m[0]) / double(eps), 1e-5 * double(one.m[0] / eps));
    }
}

TYPED_TEST(InteractionKernels, CoincidentPairWithoutSofteningContributesNothing) {
  using Real = TypeParam;
  std::mt19937 rng(16);
  Sources<Real> s = random_sources<Real>(30, rng);
  Group<Real> g = group_of(s, 4, 18, rng);  // sources 4 … 21 coincide with the targets
  for (Kind kind : kKinds) {
    check_simd_against_scalar(kind, s, g, Real(0));
    // Equal to the same sum without the coincident sources, per target.
    for (KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
      Group<Real> got = g;
      apply(kind, s, got, Real(0), path);
      for (std::size_t i = 0; i < g.size(); ++i) {
        Sources<Real> rest = s;
        for (auto* a : {&rest.x, &rest.y, &rest.z, &rest.m, &rest.qxx, &rest.qxy, &rest.qxz, &rest.qyy, &rest.qyz})
          a->erase(a->begin() + std::ptrdiff_t(4 + i));
        Group<Real> one;
        for (auto [to, from] : {std::pair{&one.x, &g.x}, {&one.y, &g.y}, {&one.z, &g.z}, {&one.ax, &g.ax},
                                {&one.ay, &g.ay}, {&one.az, &g.az}, {&one.phi, &g.phi}})
          to->push_back((*from)[i]);
        const Scale sc = term_scale(rest, one, 0, kind == Kind::quadrupole);
        apply(kind, rest, one, Real(0), KernelPath::Scalar);
        const double tol = kTolerance<Real>;
        ASSERT_NEAR(double(got.ax[i]), double(one.ax[0]), tol * sc.accel[0]) << i;
        ASSERT_NEAR(double(got.ay[i]), double(one.ay[0]), tol * sc.accel[0]) << i;
        ASSERT_NEAR(double(got.az[i]), double(one.az[0]), tol * sc.accel[0]) << i;
        ASSERT_NEAR(double(got.phi[i]), double(one.phi[0]), tol * sc.potential[0]) << i;
      }
    }
  }
}

TYPED_TEST(InteractionKernels, FarAwayCells) {
  using Real = TypeParam;
  std::mt19937 rng(17);
  for (double distance : {1e2, 1e3, 1e4}) {
    // Cells of side ~ distance/100 in a cube of side ~ distance around the origin's far side.
    const Sources<Real> s = random_sources<Real>(50, rng, 0.3 * distance, distance, 0.01 * distance);
    const Group<Real> g = random_group<Real>(37, rng);
    for (Kind kind : kKinds) check_simd_against_scalar(kind, s, g, Real(1e-4));
  }
}

// A cell made of point masses: its monopole + quadrupole field approximates
// the direct sum to third order in size/distance, the monopole alone to
// second: checks the quadrupole's convention Q_ij = Σ m (3 r_i r_j − r² δ_ij).
TYPED_TEST(InteractionKernels, QuadrupoleApproximatesTheDirectSumOfACluster) {
  using Real = TypeParam;
  std::mt19937 rng(18);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::size_t k = 12;
  std::vector<double> px(k), py(k), pz(k), pm(k);
  double mass = 0, cx = 0, cy = 0, cz = 0;
  for (std::size_t j = 0; j < k; ++j) {
    px[j] = 5 + 0.5 * u(rng);
    py[j] = -3 + 0.5 * u(rng);
    pz[j] = 2 + 0.5 * u(rng);
    pm[j] = 1 + 0.5 * u(rng);
    mass += pm[j];
    cx += pm[j] * px[j];
    cy += pm[j] * py[j];
    cz += pm[j] * pz[j];
  }
  cx /= mass;
  cy /= mass;
  cz /= mass;
  double qxx = 0, qxy = 0, qxz = 0, qyy = 0, qyz = 0;
  for (std::size_t j = 0; j < k; ++j) {
    const double rx = px[j] - cx, ry = py[j] - cy, rz = pz[j] - cz, r2 = rx * rx + ry * ry + rz * rz;
    qxx += pm[j] * (3 * rx * rx - r2);
    qxy += pm[j] * 3 * rx * ry;
    qxz += pm[j] * 3 * rx * rz;
    qyy += pm[j] * (3 * ry * ry - r2);
    qyz += pm[j] * 3 * ry * rz;
  }
  Sources<Real> cell;
  cell.x = {Real(cx)};
  cell.y = {Real(cy)};
  cell.z = {Real(cz)};
  cell.m = {Real(mass)};
  cell.qxx = {Real(qxx)};
  cell.qxy = {Real(qxy)};
  cell.qxz = {Real(qxz)};
  cell.qyy = {Real(qyy)};
  cell.qyz = {Real(qyz)};
  Sources<Real> points;
  for (std::size_t j = 0; j < k; ++j) {
    points.x.push_back(Real(px[j]));
    points.y.push_back(Real(py[j]));
    points.z.push_back(Real(pz[j]));
    points.m.push_back(Real(pm[j]));
  }
  Group<Real> g = random_group<Real>(20, rng, 1.0);
  for (std::size_t i = 0; i < g.size(); ++i) g.ax[i] = g.ay[i] = g.az[i] = g.phi[i] = 0;
  const Real eps2 = Real(1e-4);
  Group<Real> direct = g, mono = g, quad = g;
  add_particle_field(points.particles(), direct.targets(), eps2, KernelPath::Scalar);
  add_cell_field(cell.cells(), mono.targets(), eps2, false, KernelPath::Scalar);
  add_cell_field(cell.cells(), quad.targets(), eps2, true, KernelPath::Scalar);
  double worst_mono = 0, worst_quad = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double norm = std::hypot(double(direct.ax[i]), double(direct.ay[i]), double(direct.az[i]));
    const double em = std::hypot(double(mono.ax[i] - direct.ax[i]), double(mono.ay[i] - direct.ay[i]),
                                 double(mono.az[i] - direct.az[i])) / norm;
    const double eq = std::hypot(double(quad.ax[i] - direct.ax[i]), double(quad.ay[i] - direct.ay[i]),
                                 double(quad.az[i] - direct.az[i])) / norm;
    worst_mono = std::max(worst_mono, em);
    worst_quad = std::max(worst_quad, eq);
    EXPECT_LT(std::abs(double(quad.phi[i] - direct.phi[i])), std::abs(double(mono.phi[i] - direct.phi[i])) + 1e-6)
        << i;
  }
  // Size/distance ~ 0.5/6: the monopole's error is ~1e-2, the quadrupole's ~1e-3.
  EXPECT_LT(worst_quad, 0.25 * worst_mono);
  EXPECT_LT(worst_quad, 5e-3);
}

// a = −∇φ for the scalar monopole + quadrupole, by central differences (double).
TEST(InteractionKernelsDouble, AccelerationIsMinusTheGradientOfThePotential) {
  std::mt19937 rng(19);
  const Sources<double> s = random_sources<double>(6, rng, 1, 4, 0.8);
  for (double eps2 : {0.0, 0.3}) {
    for (bool quadrupole : {false, true}) {
      Group<double> g = random_group<double>(10, rng);
      for (std::size_t i = 0; i < g.size(); ++i) g.ax[i] = g.ay[i] = g.az[i] = g.phi[i] = 0;
      Group<double> field = g;
      add_cell_field(s.cells(), field.targets(), eps2, quadrupole, KernelPath::Scalar);
      const double h = 1e-5;
      for (std::size_t i = 0; i < g.size(); ++i) {
        const double a[3] = {field.ax[i], field.ay[i], field.az[i]};
        const double scale = std::hypot(a[0], a[1], a[2]);
        for (int axis = 0; axis < 3; ++axis) {
          double phi[2];
          for (int side = 0; side < 2; ++side) {
            Group<double> p = g;
            std::vector<double>& coordinate = axis == 0 ? p.x : axis == 1 ? p.y : p.z;
            coordinate[i] += side == 0 ? h : -h;
            add_cell_field(s.cells(), p.targets(), eps2, quadrupole, KernelPath::Scalar);
            phi[side] = p.phi[i];
          }
          const double gradient = (phi[0] - phi[1]) / (2 * h);
          EXPECT_NEAR(a[axis], -gradient, 1e-6 * scale) << "target " << i << " axis " << axis << " eps2 " << eps2
                                                         << " quadrupole " << quadrupole;
        }
      }
    }
  }
}

// The particle kernel's scalar path is the pair law of pair_law.hpp.
TYPED_TEST(InteractionKernels, ScalarParticlesAreThePairLaw) {
  using Real = TypeParam;
  std::mt19937 rng(20);
  const Sources<Real> s = random_sources<Real>(33, rng);
  const Group<Real> g = random_group<Real>(9, rng);
  const Real eps2 = Real(1e-2);
  Group<Real> got = g;
  add_particle_field(s.particles(), got.targets(), eps2, KernelPath::Scalar);
  const Scale sc = term_scale(s, g, double(eps2), false);
  for (std::size_t i = 0; i < g.size(); ++i) {
    double ax = g.ax[i], ay = g.ay[i], az = g.az[i], phi = g.phi[i];
    for (std::size_t j = 0; j < s.size(); ++j) {
      const PairTerm<double> t = pair_term<double>(double(s.x[j] - g.x[i]), double(s.y[j] - g.y[i]),
                                                   double(s.z[j] - g.z[i]), double(s.m[j]), double(eps2));
      ax += t.accel * double(s.x[j] - g.x[i]);
      ay += t.accel * double(s.y[j] - g.y[i]);
      az += t.accel * double(s.z[j] - g.z[i]);
      phi += t.potential;
    }
    const double tol = 8 * std::numeric_limits<Real>::epsilon();
    EXPECT_NEAR(double(got.ax[i]), ax, tol * sc.accel[i]);
    EXPECT_NEAR(double(got.ay[i]), ay, tol * sc.accel[i]);
    EXPECT_NEAR(double(got.az[i]), az, tol * sc.accel[i]);
    EXPECT_NEAR(double(got.phi[i]), phi, tol * sc.potential[i]);
  }
}

// Each SIMD term against the pair law in double: the float path's
// rsqrt + Newton step stays within ~1e-6 relative, at every distance.
TYPED_TEST(InteractionKernels, SimdTermsAreAccurateAtEveryDistance) {
  using Real = TypeParam;
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1, 1), decade(-3, 3);
  Group<Real> g;
  for (std::size_t i = 0; i < 200; ++i) {
    const double r = std::pow(10.0, decade(rng));
    double d[3] = {u(rng), u(rng), u(rng)};
    const double norm = std::hypot(d[0], d[1], d[2]);
    g.x.push_back(Real(r * d[0] / norm));
    g.y.push_back(Real(r * d[1] / norm));
    g.z.push_back(Real(r * d[2] / norm));
    for (auto* a : {&g.ax, &g.ay, &g.az, &g.phi}) a->push_back(Real(0));
  }
  Sources<Real> one;
  one.x = one.y = one.z = {Real(0)};
  one.m = {Real(1.25)};
  one.qxx = one.qxy = one.qxz = one.qyy = one.qyz = {Real(0)};
  const double eps2 = 1e-8;
  const double tol = std::is_same_v<Real, float> ? 1e-6 : 1e-14;
  for (simd::Isa isa : usable_isas()) {
    simd::ScopedIsa scope(isa);
    for (Kind kind : kKinds) {
      Group<Real> got = g;
      apply(kind, one, got, Real(eps2), KernelPath::Simd);
      for (std::size_t i = 0; i < g.size(); ++i) {
        const double dx = -double(g.x[i]), dy = -double(g.y[i]), dz = -double(g.z[i]);
        const PairTerm<double> t = pair_term(dx, dy, dz, double(one.m[0]), eps2);
        const double a = std::hypot(t.accel * dx, t.accel * dy, t.accel * dz);
        const std::string what = describe(kind, isa, 1, i);
        ASSERT_NEAR(double(got.ax[i]), t.accel * dx, tol * a) << what;
        ASSERT_NEAR(double(got.ay[i]), t.accel * dy, tol * a) << what;
        ASSERT_NEAR(double(got.az[i]), t.accel * dz, tol * a) << what;
        ASSERT_NEAR(double(got.phi[i]), t.potential, tol * std::abs(t.potential)) << what;
      }
    }
  }
}

// Calling with no targets or no sources leaves everything untouched, even with null pointers.
TYPED_TEST(InteractionKernels, EmptyListsAreNoOps) {
  using Real = TypeParam;
  const Targets<Real> none{nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, 0};
  std::mt19937 rng(21);
  const Sources<Real> s = random_sources<Real>(5, rng);
  Group<Real> g = random_group<Real>(3, rng);
  const Group<Real> before = g;
  for (KernelPath path : {KernelPath::Scalar, KernelPath::Simd}) {
    add_particle_field(s.particles(), none, Real(0), path);
    add_cell_field(s.cells(), none, Real(0), true, path);
    add_particle_field(SourceParticles<Real>{nullptr, nullptr, nullptr, nullptr, 0}, g.targets(), Real(0), path);
    add_cell_field(SourceCells<Real>{nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, 0},
                   g.targets(), Real(0), true, path);
  }
  EXPECT_EQ(g.ax, before.ax);
  EXPECT_EQ(g.phi, before.phi);
}

// The same inputs give the same bits on every call (no state), per instruction set.
TYPED_TEST(InteractionKernels, RepeatableBits) {
  using Real = TypeParam;
  std::mt19937 rng(22);
  const Sources<Real> s = random_sources<Real>(77, rng);
  const Group<Real> g = group_of(s, 10, 29, rng);
  for (simd::Isa isa : usable_isas()) {
    simd::ScopedIsa scope(isa);
    Group<Real> a = g, b = g;
    add_particle_field(s.particles(10), a.targets(), Real(1e-3));
    add_cell_field(s.cells(), a.targets(), Real(1e-3), true);
    add_particle_field(s.particles(10), b.targets(), Real(1e-3));
    add_cell_field(s.cells(), b.targets(), Real(1e-3), true);
    EXPECT_EQ(a.ax, b.ax);
    EXPECT_EQ(a.ay, b.ay);
    EXPECT_EQ(a.az, b.az);
    EXPECT_EQ(a.phi, b.phi);
  }
}

}  // namespace
}  // namespace swirl::gravity
