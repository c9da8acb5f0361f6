#include "swirl/gravity/initial_conditions.hpp"

#include <algorithm>
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

// The Hernquist isotropic distribution function of the binding energy
// ε = Ψ − v²/2 in units of GM/a, 0 < ε < 1, without its constant factor
// M/(8√2 π³ a³ (GM/a)^{3/2}) (Hernquist 1990, eq. 17), q = √ε:
//   f ∝ (1 − q²)^{−5/2} [3 asin q + q (1 − q²)^{1/2} (1 − 2q²)(8q⁴ − 8q² − 3)].
// For small q the bracket cancels to O(q⁵): a rounding error there is far
// below the rejection bound near the peak, so it changes nothing.
double hernquist_df(double e) {
  if (!(e > 0)) return 0;
  const double q = std::sqrt(e);
  const double bracket = 3 * std::asin(q) + q * std::sqrt(1 - e) * (1 - 2 * e) * (8 * e * e - 8 * e - 3);
  return std::max(0.0, bracket) / std::pow(1 - e, 2.5);
}

// The largest value of a unimodal g on (0, 1), by golden-section search.
template <class G>
double unimodal_max(G g) {
  const double inv_phi = 0.6180339887498949;
  double lo = 0, hi = 1;
  double x1 = hi - inv_phi * (hi - lo), x2 = lo + inv_phi * (hi - lo);
  double g1 = g(x1), g2 = g(x2);
  for (int k = 0; k < 48; ++k) {  // the bracket shrinks to 1e-10
    if (g1 < g2) {
      lo = x1, x1 = x2, g1 = g2;
      x2 = lo + inv_phi * (hi - lo), g2 = g(x2);
    } else {
      hi = x2, x2 = x1, g2 = g1;
      x1 = hi - inv_phi * (hi - lo), g1 = g(x1);
    }
  }
  return std::max(g1, g2);
}

// One Hernquist halo, G = M = 1, scale radius 1 (structural units), centre of mass not yet removed.
void add_hernquist(Sample& s, std::size_t n, SplitMix64& rng, double mass_cut) {
  for (std::size_t i = 0; i < n; ++i) {
    // Enclosed mass m = r²/(1 + r)² inverted: r = √m/(1 − √m); m > 0 keeps r > 0 (Ψ < 1).
    double m = 0;
    while (!(m > 0)) m = mass_cut * rng.uniform();
    const double r = std::sqrt(m) / (1 - std::sqrt(m));
    const double psi = 1 / (1 + r);
    // v = x·v_esc, v_esc = √(2Ψ): the density of x is ∝ x² f(Ψ(1 − x²)) on (0, 1).
    const auto density = [psi](double x) { return x * x * hernquist_df(psi * (1 - x * x)); };
    const double bound = 1.1 * unimodal_max(density);
    double x = 0, y = 1;
    while (y > density(x)) {
      x = rng.uniform();
      y = bound * rng.uniform();
    }
    s.x.push_back(isotropic(rng, r));
    s.v.push_back(isotropic(rng, x * std::sqrt(2 * psi)));
    s.m.push_back(1 / double(n));
  }
}

// The centre of mass of particles [begin, end) and its velocity.
struct Centre {
  V3 position{}, velocity{};
};
Centre centre_of_mass(const Sample& s, std::size_t begin, std::size_t end) {
  double mass = 0;
  V3 mx{}, mv{};
  for (std::size_t i = begin; i < end; ++i) {
    mass += s.m[i];
    for (std::size_t a = 0; a < 3; ++a) {
      mx[a] += s.m[i] * s.x[i][a];
      mv[a] += s.m[i] * s.v[i][a];
    }
  }
  Centre c;
  for (std::size_t a = 0; a < 3; ++a) c.position[a] = mx[a] / mass, c.velocity[a] = mv[a] / mass;
  return c;
}

// Shifts particles [begin, end) so that their centre of mass is at x0 moving with v0.
void recentre(Sample& s, std::size_t begin, std::size_t end, const V3& x0, const V3& v0) {
  const Centre c = centre_of_mass(s, begin, end);
  for (std::size_t i = begin; i < end; ++i)
    for (std::size_t a = 0; a < 3; ++a) {
      s.x[i][a] += x0[a] - c.position[a];
      s.v[i][a] += v0[a] - c.velocity[a];
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
ParticleSet<Real> hernquist(std::size_t n, std::uint64_t seed, const HernquistOptions& options) {
  require_particles("hernquist", n);
  const double a = options.scale_radius;
  require(a > 0 && std::isfinite(a), "hernquist", "scale_radius", a, "finite and > 0");
  require(options.mass_cut > 0 && options.mass_cut < 1, "hernquist", "mass_cut", options.mass_cut, "in (0, 1)");
  SplitMix64 rng(seed);
  Sample s;
  add_hernquist(s, n, rng, options.mass_cut);
  // Structural units (a = 1) → scale radius a: lengths × a, velocities × (GM/a)^{1/2}.
  const double speed = 1 / std::sqrt(a);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      s.x[i][k] *= a;
      s.v[i][k] *= speed;
    }
  // Only the velocity of the centre of mass is removed: the ρ ∝ r⁻⁴ tail moves the
  // sample's centre of mass by about √(2 a r_max / 3N) from the cusp (0.05 a at
  // N = 65 536), and the cusp, not that point, is the halo's centre.
  const V3 drift = centre_of_mass(s, 0, n).velocity;
  for (V3& v : s.v)
    for (std::size_t k = 0; k < 3; ++k) v[k] -= drift[k];
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
template ParticleSet<float> hernquist<float>(std::size_t, std::uint64_t, const HernquistOptions&);
template ParticleSet<double> hernquist<double>(std::size_t, std::uint64_t, const HernquistOptions&);
template ParticleSet<float> uniform_sphere<float>(std::size_t, std::uint64_t, double, double);
template ParticleSet<double> uniform_sphere<double>(std::size_t, std::uint64_t, double, double);
template ParticleSet<float> uniform_cube<float>(std::size_t, std::uint64_t, double, double);
template ParticleSet<double> uniform_cube<double>(std::size_t, std::uint64_t, double, double);
template ParticleSet<float> cold_collapse<float>(std::size_t, std::uint64_t);
template ParticleSet<double> cold_collapse<double>(std::size_t, std::uint64_t);
template ParticleSet<float> plummer_collision<float>(std::size_t, std::uint64_t, const CollisionOptions&);
template ParticleSet<double> plummer_collision<double>(std::size_t, std::uint64_t, const CollisionOptions&);

}  // namespace swirl::gravity
