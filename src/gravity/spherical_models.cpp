#include "swirl/gravity/spherical_models.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "spherical_df.hpp"

namespace swirl::gravity {

namespace {

constexpr double kPi = 3.14159265358979323846;
using detail::RadialTable;
using detail::V3;

// Radius-grid nodes per e-folding: the tables' interpolation and the
// Eddington quadrature err by ~(1/200)² relative, far below sampling noise.
constexpr double kNodesPerEfold = 200;

void require(bool ok, const char* what, const char* name, double value, const char* range) {
  if (!ok) throw std::invalid_argument(fmt::format("{}: {} = {} must be {}", what, name, value, range));
}

// n nodes from a to b, equally spaced in ln r, a excluded and b included.
void append_log_nodes(std::vector<double>& r, double a, double b) {
  const auto n = std::size_t(std::ceil(std::log(b / a) * kNodesPerEfold));
  for (std::size_t k = 1; k <= n; ++k) r.push_back(k == n ? b : a * std::exp(std::log(b / a) * double(k) / double(n)));
}

// The particles of a tabulated model (structural units, G = 1) scaled by
// `length` and `speed`, equal masses 1/N.
template <class Real>
ParticleSet<Real> to_particles(const std::vector<V3>& x, const std::vector<V3>& v, double length, double speed) {
  const std::size_t n = x.size();
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      p.position[int(a)][i] = Real(x[i][a] * length);
      p.velocity[int(a)][i] = Real(v[i][a] * speed);
    }
    p.mass[i] = Real(1 / double(n));
    p.id[i] = i;
  }
  return p;
}

// Subtracts the mean (equal masses) of the vectors.
void remove_mean(std::vector<V3>& u) {
  V3 mean{};
  for (const V3& a : u)
    for (std::size_t k = 0; k < 3; ++k) mean[k] += a[k];
  for (double& c : mean) c /= double(u.size());
  for (V3& a : u)
    for (std::size_t k = 0; k < 3; ++k) a[k] -= mean[k];
}

// ---- NFW --------------------------------------------------------------------

// The truncated NFW profile in structural units: r_s = 1 and ρ = 1/(x (1 + x)²)
// inside c (so M(x) = 4π [ln(1 + x) − x/(1 + x)] there), the exponential tail outside.
struct NfwProfile {
  double c, xd, kappa, rho_c;
  NfwProfile(double concentration, double decay)
      : c(concentration), xd(decay * concentration),
        kappa(-(1 + 3 * concentration) / (1 + concentration) + 1 / decay),
        rho_c(1 / (concentration * (1 + concentration) * (1 + concentration))) {}
  double rho(double x) const {
    return x <= c ? 1 / (x * (1 + x) * (1 + x)) : rho_c * std::pow(x / c, kappa) * std::exp(-(x - c) / xd);
  }
  double drho(double x) const { return x <= c ? -rho(x) * (1 / x + 2 / (1 + x)) : rho(x) * (kappa / x - 1 / xd); }
  double inner_mass(double x) const { return 4 * kPi * (std::log1p(x) - x / (1 + x)); }
};

struct NfwModel {
  RadialTable table;
  detail::TabulatedDf df;
};

NfwModel nfw_model(const NfwOptions& o) {
  const NfwProfile p(o.concentration, o.decay);
  NfwModel model;
  std::vector<double>& r = model.table.r;
  // From 10⁻⁶ r_s (holding ~10⁻¹² of the mass: no sample reaches it) to c,
  // then on until the tail's mass per e-folding, 4π x³ ρ, is below 10⁻¹⁶ of
  // the total: c is a node, so the kink in ρ″ there falls between intervals.
  const double x_min = 1e-6;
  r.push_back(x_min);
  append_log_nodes(r, x_min, p.c);
  const std::size_t n_inner = r.size();
  const double step = std::exp(1 / kNodesPerEfold);
  while (4 * kPi * std::pow(r.back(), 3) * p.rho(r.back()) > 1e-16 * p.inner_mass(p.c) || r.back() < 2 * p.c)
    r.push_back(r.back() * step);
  const std::size_t n = r.size();
  // Mass: closed form inside c, then the trapezoidal rule in ln x on 4π x³ ρ.
  std::vector<double>& m = model.table.mass;
  m.resize(n);
  for (std::size_t k = 0; k < n_inner; ++k) m[k] = p.inner_mass(r[k]);
  const auto shell = [&](std::size_t k, int power) {
    return 0.5 * std::log(r[k] / r[k - 1]) *
           (4 * kPi * std::pow(r[k], power) * p.rho(r[k]) + 4 * kPi * std::pow(r[k - 1], power) * p.rho(r[k - 1]));
  };
  for (std::size_t k = n_inner; k < n; ++k) m[k] = m[k - 1] + shell(k, 3);
  // Ψ(x) = M(x)/x + ∫ₓ^∞ 4π ρ s ds: the outer integral by the trapezoidal
  // rule in ln s from the last node in, closed form 4π [1/(1 + x) − 1/(1 + c)] inside c.
  std::vector<double> outer(n, 0.0);
  for (std::size_t k = n - 1; k >= n_inner; --k) outer[k - 1] = outer[k] + shell(k, 2);
  std::vector<double>& psi = model.table.psi;
  psi.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double beyond = k + 1 < n_inner ? 4 * kPi * (1 / (1 + r[k]) - 1 / (1 + p.c)) + outer[n_inner - 1] : outer[k];
    psi[k] = m[k] / r[k] + beyond;
  }
  std::vector<double> q(n);
  for (std::size_t k = 0; k < n; ++k) q[k] = -p.drho(r[k]) * r[k] * r[k] / m[k];  // dρ/dΨ = ρ′ / (−M/r²)
  model.df = detail::eddington(model.table, q);
  const double negative = detail::most_negative_fraction(model.df);
  if (!(negative >= -1e-6))
    throw std::invalid_argument(
        fmt::format("nfw: decay = {} is too sharp a truncation for concentration = {}: no isotropic distribution "
                    "function makes this density (f(E) reaches {:.2g} of its peak); raise decay",
                    o.decay, o.concentration, negative));
  return model;
}

// ---- King -------------------------------------------------------------------

// ρ(W) without its constant factor, e^W erf(√W) − √(4W/π)(1 + 2W/3), from the
// series e^{x²} erf(x) = (2/√π) Σₙ 2ⁿ x^{2n+1}/(2n + 1)!!, whose first two
// terms are the subtracted ones: ρ = (2/√π) Σ_{n≥2} 2ⁿ W^{n+½}/(2n + 1)!!. All
// terms are positive, so there is no cancellation near the tidal radius.
double king_density(double w) {
  if (!(w > 0)) return 0;
  double term = (2 / std::sqrt(kPi)) * std::sqrt(w) * (2 * w / 3) * (2 * w / 5);  // n = 2
  double sum = 0;
  for (int k = 2; k < 400; ++k) {
    sum += term;
    if (term < 1e-17 * sum && k > w) break;
    term *= 2 * w / (2 * k + 3);
  }
  return sum;
}

struct KingModel {
  RadialTable table;  // r in King radii, mass μ = −r² W′, Ψ = W
  double tidal_radius = 0;
};

// Poisson's equation in s = ln r with p = dW/ds: W′ = p, p′ = −p − 9 r² ρ(W)/ρ(W₀),
// from the series W = W₀ − (3/2) r², p = −3r² at r = 10⁻⁴ (the next terms are
// O(r⁴)), RK4 with 1/kNodesPerEfold steps; the last step is shortened by the
// secant method to end on W = 0.
KingModel king_model(double w0) {
  const double rho0 = king_density(w0);
  const auto rhs = [rho0](double s, double w, double pw, double& dw, double& dp) {
    dw = pw;
    dp = -pw - 9 * std::exp(2 * s) * king_density(w) / rho0;
  };
  const auto rk4 = [&](double s, double w, double pw, double h, double& w1, double& p1) {
    double k1w, k1p, k2w, k2p, k3w, k3p, k4w, k4p;
    rhs(s, w, pw, k1w, k1p);
    rhs(s + h / 2, w + h / 2 * k1w, pw + h / 2 * k1p, k2w, k2p);
    rhs(s + h / 2, w + h / 2 * k2w, pw + h / 2 * k2p, k3w, k3p);
    rhs(s + h, w + h * k3w, pw + h * k3p, k4w, k4p);
    w1 = w + h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    p1 = pw + h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p);
  };
  KingModel model;
  RadialTable& t = model.table;
  const double r0 = 1e-4, h = 1 / kNodesPerEfold;
  double s = std::log(r0), w = w0 - 1.5 * r0 * r0, pw = -3 * r0 * r0;
  const auto push = [&](double s_, double w_, double p_) {
    t.r.push_back(std::exp(s_));
    t.psi.push_back(std::max(0.0, w_));
    t.mass.push_back(-std::exp(s_) * p_);  // μ = −r² dW/dr = −r p
  };
  push(s, w, pw);
  for (;;) {
    double w1, p1;
    rk4(s, w, pw, h, w1, p1);
    if (w1 > 0) {
      s += h, w = w1, pw = p1;
      push(s, w, pw);
      if (s > 50) throw std::logic_error("king: the tidal radius was not reached");
      continue;
    }
    // The root lies within this step: secant iterations on the step length.
    double ha = 0, wa = w, hb = h, wb = w1, pb = p1;
    for (int k = 0; k < 60 && std::abs(wb) > 1e-15 * w0; ++k) {
      const double hc = hb - wb * (hb - ha) / (wb - wa);
      double wc, pc;
      rk4(s, w, pw, hc, wc, pc);
      ha = hb, wa = wb, hb = hc, wb = wc, pb = pc;
    }
    push(s + hb, 0.0, pb);
    break;
  }
  model.tidal_radius = t.r.back();
  return model;
}

// Lengths and speeds that take a tabulated model of mass M and potential energy
// W (G = 1) to Hénon units: M → 1 and W → −1/2 (E = W/2 = −1/4 in virial equilibrium).
struct HenonScale {
  double length, speed;
};
HenonScale henon_scale(const RadialTable& t) {
  const double m = t.mass.back(), w = detail::potential_energy(t);
  const double length = 2 * std::abs(w) / (m * m);
  return {length, std::sqrt(1 / (m * length))};
}

void require_particles(const char* what, std::size_t n) {
  if (n == 0) throw std::invalid_argument(fmt::format("{}: the particle count must be at least 1 (got 0)", what));
}

void check_king(const KingOptions& o) {
  require(o.w0 >= 0.1 && o.w0 <= 16, "king", "w0", o.w0, "in [0.1, 16]");
}

}  // namespace

template <class Real>
ParticleSet<Real> nfw(std::size_t n, std::uint64_t seed, const NfwOptions& o) {
  require_particles("nfw", n);
  require(o.concentration >= 1 && o.concentration <= 100, "nfw", "concentration", o.concentration, "in [1, 100]");
  require(o.decay >= 0.01 && o.decay <= 1, "nfw", "decay", o.decay, "in [0.01, 1]");
  if (o.virial_radius)
    require(*o.virial_radius > 0 && std::isfinite(*o.virial_radius), "nfw", "virial_radius", *o.virial_radius,
            "finite and > 0");
  const NfwModel model = nfw_model(o);
  const RadialTable& t = model.table;
  SplitMix64 rng(seed);
  std::vector<V3> x, v;
  x.reserve(n);
  v.reserve(n);
  const auto f = [&model](double e) { return model.df(e); };
  const auto majorant = [&model](double e) { return model.df.majorant(e); };
  for (std::size_t i = 0; i < n; ++i) {
    double m = 0;
    while (!(m > 0)) m = t.mass.back() * rng.uniform();
    const double r = t.radius_of_mass(m);
    x.push_back(detail::isotropic_vector(rng, r));
    v.push_back(detail::isotropic_vector(rng, detail::sample_speed(rng, t.psi_at(r), f, majorant)));
  }
  // Structural units (r_s = 1, mass M_t) → M = 1 and r_vir as asked, or Hénon units.
  HenonScale scale = henon_scale(t);
  if (o.virial_radius) {
    scale.length = *o.virial_radius / o.concentration;
    scale.speed = std::sqrt(1 / (t.mass.back() * scale.length));
  }
  // Only the velocity of the centre of mass is removed: the cusp, not the
  // sample's centre of mass, is the halo's centre.
  remove_mean(v);
  return to_particles<Real>(x, v, scale.length, scale.speed);
}

template <class Real>
ParticleSet<Real> king(std::size_t n, std::uint64_t seed, const KingOptions& o) {
  require_particles("king", n);
  check_king(o);
  const KingModel model = king_model(o.w0);
  const RadialTable& t = model.table;
  SplitMix64 rng(seed);
  std::vector<V3> x, v;
  x.reserve(n);
  v.reserve(n);
  // f ∝ exp(ε) − 1 with ε in units of σ².
  // It does not decrease, so it is its own majorant.
  const auto f = [](double e) { return e > 0 ? std::expm1(e) : 0.0; };
  for (std::size_t i = 0; i < n; ++i) {
    double m = 0;
    while (!(m > 0)) m = t.mass.back() * rng.uniform();
    const double r = t.radius_of_mass(m);
    x.push_back(detail::isotropic_vector(rng, r));
    v.push_back(detail::isotropic_vector(rng, detail::sample_speed(rng, t.psi_at(r), f, f)));
  }
  remove_mean(x);
  remove_mean(v);
  const HenonScale scale = henon_scale(t);
  return to_particles<Real>(x, v, scale.length, scale.speed);
}

KingScales king_scales(const KingOptions& o) {
  check_king(o);
  const KingModel model = king_model(o.w0);
  const HenonScale scale = henon_scale(model.table);
  // σ² is the unit of Ψ, and Ψ ∝ M/r scales as speed².
  return {scale.length, model.tidal_radius * scale.length, scale.speed,
          model.table.radius_of_mass(0.5 * model.table.mass.back()) * scale.length};
}

template ParticleSet<float> nfw<float>(std::size_t, std::uint64_t, const NfwOptions&);
template ParticleSet<double> nfw<double>(std::size_t, std::uint64_t, const NfwOptions&);
template ParticleSet<float> king<float>(std::size_t, std::uint64_t, const KingOptions&);
template ParticleSet<double> king<double>(std::size_t, std::uint64_t, const KingOptions&);

}  // namespace swirl::gravity
