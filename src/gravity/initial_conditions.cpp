#include "swirl/gravity/initial_conditions.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/random.hpp"

namespace swirl::gravity {

namespace {

constexpr double kPi = 3.14159265358979323846;
using V3 = std::array<double, 3>;

// Positions and velocities in double before they become particles.
struct Sample {
  std::vector<V3> x, v;
  std::vector<double> m;
};

void require_particles(const char* what, std::size_t n) {
  if (n == 0) throw std::invalid_argument(fmt::format("{}: the particle count must be at least 1 (got 0)", what));
}

void require(bool ok, const char* what, const char* name, double value, const char* range) {
  if (!ok) throw std::invalid_argument(fmt::format("{}: {} = {} must be {}", what, name, value, range));
}

// A vector of length r in a uniformly random direction (cos θ and φ uniform).
V3 isotropic(SplitMix64& rng, double r) {
  const double z = 1 - 2 * rng.uniform();
  const double rho = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * kPi * rng.uniform();
  return {r * rho * std::cos(phi), r * rho * std::sin(phi), r * z};
}

// One Plummer sphere, G = M = 1, Hénon units, centre of mass not yet removed.
void add_plummer(Sample& s, std::size_t n, SplitMix64& rng, double mass_cut, double mass) {
  // Structural units (scale radius 1) → Hénon units: lengths × 3π/16, velocities × (16/3π)^{1/2}.
  const double length = kPlummerScale, speed = std::sqrt(1 / kPlummerScale);
  for (std::size_t i = 0; i < n; ++i) {
    // Enclosed mass m(r) = r³/(r² + 1)^{3/2} inverted: r = (m^{−2/3} − 1)^{−1/2}.
    const double m = mass_cut * rng.uniform();
    const double r = 1 / std::sqrt(std::pow(m, -2.0 / 3.0) - 1);
    // Speed q·v_esc, v_esc = √2 (1 + r²)^{−1/4}; q by rejection from g(q) = q²(1 − q²)^{7/2} ≤ 0.1.
    double q = 0, y = 1;
    while (y > q * q * std::pow(1 - q * q, 3.5)) {
      q = rng.uniform();
      y = 0.1 * rng.uniform();
    }
    const double v = q * std::sqrt(2.0) * std::pow(1 + r * r, -0.25);
    s.x.push_back(isotropic(rng, r * length));
    s.v.push_back(isotropic(rng, v * speed));
    s.m.push_back(mass / double(n));
  }
}

// Shifts particles [begin, end) so that their centre of mass is at x0 moving with v0.
void recentre(Sample& s, std::size_t begin, std::size_t end, const V3& x0, const V3& v0) {
  double mass = 0;
  V3 mx{}, mv{};
  for (std::size_t i = begin; i < end; ++i) {
    mass += s.m[i];
    for (std::size_t a = 0; a < 3; ++a) {
      mx[a] += s.m[i] * s.x[i][a];
      mv[a] += s.m[i] * s.v[i][a];
    }
  }
  for (std::size_t i = begin; i < end; ++i)
    for (std::size_t a = 0; a < 3; ++a) {
      s.x[i][a] += x0[a] - mx[a] / mass;
      s.v[i][a] += v0[a] - mv[a] / mass;
    }
}

template <class Real>
ParticleSet<Real> to_particles(const Sample& s) {
  ParticleSet<Real> p(s.x.size());
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      p.position[a][i] = Real(s.x[i][std::size_t(a)]);
      p.velocity[a][i] = Real(s.v[i][std::size_t(a)]);
    }
    p.mass[i] = Real(s.m[i]);
    p.id[i] = i;
  }
  return p;
}

}  // namespace

template <class Real>
ParticleSet<Real> plummer(std::size_t n, std::uint64_t seed, const PlummerOptions& options) {
  require_particles("plummer", n);
  require(options.mass_cut > 0 && options.mass_cut <= 1, "plummer", "mass_cut", options.mass_cut, "in (0, 1]");
  SplitMix64 rng(seed);
  Sample s;
  add_plummer(s, n, rng, options.mass_cut, 1.0);
  recentre(s, 0, n, {}, {});
  return to_particles<Real>(s);
}

template <class Real>
ParticleSet<Real> uniform_sphere(std::size_t n, std::uint64_t seed, double radius, double mass) {
  require_particles("uniform_sphere", n);
  require(radius > 0 && std::isfinite(radius), "uniform_sphere", "radius", radius, "finite and > 0");
  require(mass > 0 && std::isfinite(mass), "uniform_sphere", "mass", mass, "finite and > 0");
  SplitMix64 rng(seed);
  Sample s;
  for (std::size_t i = 0; i < n; ++i) {
    // Enclosed volume ∝ r³ is uniform: r = R·u^{1/3}.
    s.x.push_back(isotropic(rng, radius * std::cbrt(rng.uniform())));
    s.v.push_back({});
    s.m.push_back(mass / double(n));
  }
  return to_particles<Real>(s);
}

template <class Real>
ParticleSet<Real> uniform_cube(std::size_t n, std::uint64_t seed, double side, double mass) {
  require_particles("uniform_cube", n);
  require(side > 0 && std::isfinite(side), "uniform_cube", "side", side, "finite and > 0");
  require(mass > 0 && std::isfinite(mass), "uniform_cube", "mass", mass, "finite and > 0");
  SplitMix64 rng(seed);
  Sample s;
  for (std::size_t i = 0; i < n; ++i) {
    V3 x{};
    for (double& c : x) c = (rng.uniform() - 0.5) * side;
    s.x.push_back(x);
    s.v.push_back({});
    s.m.push_back(mass / double(n));
  }
  return to_particles<Real>(s);
}

template <class Real>
ParticleSet<Real> cold_collapse(std::size_t n, std::uint64_t seed) {
  require_particles("cold_collapse", n);
  return uniform_sphere<Real>(n, seed, 1.0, 1.0);
}

template <class Real>
ParticleSet<Real> plummer_collision(std::size_t n, std::uint64_t seed, const CollisionOptions& o) {
  const char* what = "plummer_collision";
  require_particles(what, n);
  const double f = o.mass_fraction, d = o.separation, b = o.impact_parameter;
  require(f > 0 && f < 1, what, "mass_fraction", f, "in (0, 1)");
  require(d > 0 && std::isfinite(d), what, "separation", d, "finite and > 0");
  require(b >= 0 && b < d, what, "impact_parameter", b, "in [0, separation)");
  require(o.mass_cut > 0 && o.mass_cut <= 1, what, "mass_cut", o.mass_cut, "in (0, 1]");
  const double v = o.relative_velocity.value_or(std::sqrt(2.0 / d));  // parabolic: ½v² = M/d
  require(v >= 0 && std::isfinite(v), what, "relative_velocity", v, "finite and >= 0");
  const auto n1 = std::size_t(std::llround(f * double(n)));
  if (n1 == 0 || n1 == n)
    throw std::invalid_argument(fmt::format("{}: {} particles cannot be split {} : {} with at least one per sphere",
                                            what, n, f, 1 - f));

  const std::array<double, 2> mass{f, 1 - f};
  const std::array<std::size_t, 3> bound{0, n1, n};
  const V3 r_rel{std::sqrt(d * d - b * b), b, 0}, v_rel{-v, 0, 0};
  SplitMix64 rng(seed);
  Sample s;
  for (std::size_t k = 0; k < 2; ++k) {
    const std::size_t begin = bound[k], end = bound[k + 1];
    add_plummer(s, end - begin, rng, o.mass_cut, mass[k]);
    // A unit sphere scaled to mass M_k and length M_k^{1/3} stays virialised
    // with velocities × (M_k / M_k^{1/3})^{1/2} (its masses are already M_k / n_k).
    const double length = std::cbrt(mass[k]), speed = std::sqrt(mass[k] / length);
    for (std::size_t i = begin; i < end; ++i)
      for (std::size_t a = 0; a < 3; ++a) {
        s.x[i][a] *= length;
        s.v[i][a] *= speed;
      }
    // Sphere 1 at −(M₂/M)·r_rel, sphere 2 at +(M₁/M)·r_rel: the pair's centre of mass at rest at 0.
    const double share = k == 0 ? -mass[1] : mass[0];
    recentre(s, begin, end, {share * r_rel[0], share * r_rel[1], share * r_rel[2]},
             {share * v_rel[0], share * v_rel[1], share * v_rel[2]});
  }
  recentre(s, 0, n, {}, {});
  return to_particles<Real>(s);
}

template ParticleSet<float> plummer<float>(std::size_t, std::uint64_t, const PlummerOptions&);
template ParticleSet<double> plummer<double>(std::size_t, std::uint64_t, const PlummerOptions&);
template ParticleSet<float> uniform_sphere<float>(std::size_t, std::uint64_t, double, double);
template ParticleSet<double> uniform_sphere<double>(std::size_t, std::uint64_t, double, double);
template ParticleSet<float> uniform_cube<float>(std::size_t, std::uint64_t, double, double);
template ParticleSet<double> uniform_cube<double>(std::size_t, std::uint64_t, double, double);
template ParticleSet<float> cold_collapse<float>(std::size_t, std::uint64_t);
template ParticleSet<double> cold_collapse<double>(std::size_t, std::uint64_t);
template ParticleSet<float> plummer_collision<float>(std::size_t, std::uint64_t, const CollisionOptions&);
template ParticleSet<double> plummer_collision<double>(std::size_t, std::uint64_t, const CollisionOptions&);

}  // namespace swirl::gravity
