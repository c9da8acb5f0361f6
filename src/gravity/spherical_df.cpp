#include "spherical_df.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace swirl::gravity::detail {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

V3 isotropic_vector(SplitMix64& rng, double r) {
  const double z = 1 - 2 * rng.uniform();
  const double rho = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * kPi * rng.uniform();
  return {r * rho * std::cos(phi), r * rho * std::sin(phi), r * z};
}

double normal_deviate(SplitMix64& rng) {
  // 1 − u is in (0, 1], so the logarithm is finite.
  const double u1 = 1 - rng.uniform(), u2 = rng.uniform();
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
}

double RadialTable::radius_of_mass(double m) const {
  const auto it = std::lower_bound(mass.begin(), mass.end(), m);
  if (it == mass.end()) return r.back();
  std::size_t k = std::size_t(it - mass.begin());
  if (k == 0) k = 1;  // below the first node: the first two nodes' power law
  const double t = std::log(m / mass[k - 1]) / std::log(mass[k] / mass[k - 1]);
  return r[k - 1] * std::exp(t * std::log(r[k] / r[k - 1]));
}

double RadialTable::psi_at(double radius) const {
  if (radius <= r.front()) return psi.front();
  if (radius >= r.back()) return psi.back() * r.back() / radius;
  const std::size_t k = std::size_t(std::upper_bound(r.begin(), r.end(), radius) - r.begin());
  const double t = (radius - r[k - 1]) / (r[k] - r[k - 1]);
  return psi[k - 1] + t * (psi[k] - psi[k - 1]);
}

double TabulatedDf::majorant(double e) const {
  const std::size_t k = std::size_t(std::upper_bound(energy.begin(), energy.end(), e) - energy.begin());
  return std::max(k == 0 ? 0.0 : running_max[k - 1], (*this)(e));
}

double TabulatedDf::operator()(double e) const {
  if (!(e > 0)) return 0;
  if (e >= energy.back()) return f.back();
  const std::size_t k = std::size_t(std::upper_bound(energy.begin(), energy.end(), e) - energy.begin());
  const double e0 = k == 0 ? 0.0 : energy[k - 1], f0 = k == 0 ? 0.0 : f[k - 1];
  return f0 + (e - e0) / (energy[k] - e0) * (f[k] - f0);
}

TabulatedDf eddington(const RadialTable& table, const std::vector<double>& drho_dpsi) {
  const std::size_t n = table.r.size();
  const auto psi = [&](std::size_t k) { return k < n ? table.psi[k] : 0.0; };
  const auto q = [&](std::size_t k) { return k < n ? drho_dpsi[k] : 0.0; };
  // G(ε_j) = ∫₀^{ε_j} q dΨ/√(ε_j − Ψ), ε_j = Ψ_j. On the interval [Ψ_{k+1}, Ψ_k]
  // write u = ε − Ψ and q = A − s·u (linear): ∫ (A − s u) u^{−1/2} du =
  // 2A√u − (2/3) s u^{3/2} between u_lo = ε − Ψ_k and u_hi = ε − Ψ_{k+1}.
  std::vector<double> g(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double e = psi(j);
    double sum = 0;
    for (std::size_t k = j; k < n; ++k) {
      const double lo = e - psi(k), hi = e - psi(k + 1);
      const double s = (q(k + 1) - q(k)) / (psi(k + 1) - psi(k));
      const double a = q(k) + s * lo;
      const double root_lo = std::sqrt(lo), root_hi = std::sqrt(hi);
      sum += 2 * a * (root_hi - root_lo) - (2.0 / 3.0) * s * (hi * root_hi - lo * root_lo);
    }
    g[j] = sum;
  }
  // Ascending energies E_m = Ψ_{n−1−m}; f = G′/(√8 π²) by the three-point rule on
  // unequal steps, with G(0) = 0 as the point below the first and a one-sided
  // rule at the last (the centre's energy).
  TabulatedDf df;
  df.energy.resize(n);
  df.f.resize(n);
  std::vector<double> big_g(n);
  for (std::size_t m = 0; m < n; ++m) df.energy[m] = psi(n - 1 - m), big_g[m] = g[n - 1 - m];
  const double norm = 1 / (std::sqrt(8.0) * kPi * kPi);
  for (std::size_t m = 0; m < n; ++m) {
    double x0, x1, x2, g0, g1, g2;
    if (m + 1 < n) {
      x0 = m == 0 ? 0.0 : df.energy[m - 1], g0 = m == 0 ? 0.0 : big_g[m - 1];
      x1 = df.energy[m], g1 = big_g[m];
      x2 = df.energy[m + 1], g2 = big_g[m + 1];
      const double h1 = x1 - x0, h2 = x2 - x1;
      df.f[m] = norm * (-h2 / (h1 * (h1 + h2)) * g0 + (h2 - h1) / (h1 * h2) * g1 + h1 / (h2 * (h1 + h2)) * g2);
    } else {
      x0 = df.energy[m - 2], g0 = big_g[m - 2];
      x1 = df.energy[m - 1], g1 = big_g[m - 1];
      x2 = df.energy[m], g2 = big_g[m];
      const double h1 = x1 - x0, h2 = x2 - x1;
      df.f[m] = norm * (h2 / (h1 * (h1 + h2)) * g0 - (h1 + h2) / (h1 * h2) * g1 + (h1 + 2 * h2) / (h2 * (h1 + h2)) * g2);
    }
  }
  df.running_max.resize(n);
  for (std::size_t m = 0; m < n; ++m) df.running_max[m] = std::max(m == 0 ? 0.0 : df.running_max[m - 1], df.f[m]);
  return df;
}

double most_negative_fraction(const TabulatedDf& df) {
  const auto [lo, hi] = std::minmax_element(df.f.begin(), df.f.end());
  return *hi > 0 ? std::min(0.0, *lo) / *hi : -1.0;
}

double sample_speed(SplitMix64& rng, double psi, const std::function<double(double)>& f,
                    const std::function<double(double)>& majorant) {
  // x = v/v_esc has the density x² f(Ψ(1 − x²)) on (0, 1).
  constexpr int bins = 64;
  std::array<double, bins> bound{};
  double total = 0;
  for (int k = 0; k < bins; ++k) {
    const double lo = double(k) / bins, hi = double(k + 1) / bins;
    bound[std::size_t(k)] = hi * hi * majorant(psi * (1 - lo * lo));
    total += bound[std::size_t(k)];
  }
  // Both refusals are reachable only from extreme parameters (overflowing tables): invalid_argument,
  // which the scene reports against the source.
  if (!(total > 0 && std::isfinite(total)))
    throw std::invalid_argument(fmt::format("no speed can be drawn at Ψ = {} (envelope {})", psi, total));
  // The envelope is within a factor ~3 of the density for a smooth f: 10⁷ proposals never run out.
  for (long tries = 0; tries < 10'000'000; ++tries) {
    // A bin by its share of the envelope, a point uniform in it, accepted with density/bound.
    double pick = total * rng.uniform();
    std::size_t k = 0;
    while (k + 1 < bins && pick >= bound[k]) pick -= bound[k++];
    const double x = (double(k) + rng.uniform()) / bins;
    const double y = bound[k] * rng.uniform();
    if (y < x * x * f(psi * (1 - x * x))) return x * std::sqrt(2 * psi);
  }
  throw std::invalid_argument(fmt::format("no speed drawn in 10⁷ tries at Ψ = {}", psi));
}

double potential_energy(const RadialTable& table) {
  // The core inside the first node holds a negligible mass (≲ 10⁻⁹ of the model).
  double w = 0.5 * table.mass.front() * table.mass.front() / table.r.front();
  for (std::size_t k = 1; k < table.r.size(); ++k)
    w += 0.5 * (table.mass[k] - table.mass[k - 1]) *
         (table.mass[k] / table.r[k] + table.mass[k - 1] / table.r[k - 1]);
  return -w;
}

}  // namespace swirl::gravity::detail
