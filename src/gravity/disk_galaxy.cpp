#include "swirl/gravity/disk_galaxy.hpp"

#include <math.h>  // j0, j1 (POSIX)

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "spherical_df.hpp"

namespace swirl::gravity {

namespace {

constexpr double kPi = 3.14159265358979323846;
using detail::RadialTable;
using detail::V3;

// The radius where Hernquist (1993) fixes Toomre's Q: the Sun's, 8.5 kpc for
// a 3.5 kpc scale length.
constexpr double kReferenceRadius = 2.43;  // scale lengths

void require(bool ok, const char* name, double value, const char* range) {
  if (!ok) throw std::invalid_argument(fmt::format("disk_galaxy: {} = {} must be {}", name, value, range));
}

void check(const DiskGalaxyOptions& o) {
  const auto finite_positive = [](double x) { return x > 0 && std::isfinite(x); };
  require(o.disk_mass > 0 && o.disk_mass < 1, "disk_mass", o.disk_mass, "in (0, 1)");
  require(finite_positive(o.disk_scale_length), "disk_scale_length", o.disk_scale_length, "finite and > 0");
  require(finite_positive(o.disk_scale_height), "disk_scale_height", o.disk_scale_height, "finite and > 0");
  require(o.disk_cut >= 2 && o.disk_cut <= 50, "disk_cut", o.disk_cut, "in [2, 50]");
  require(finite_positive(o.toomre_q), "toomre_q", o.toomre_q, "finite and > 0");
  require(finite_positive(o.halo_scale_radius), "halo_scale_radius", o.halo_scale_radius, "finite and > 0");
  require(o.halo_mass_cut > 0 && o.halo_mass_cut < 1, "halo_mass_cut", o.halo_mass_cut, "in (0, 1)");
  require(o.disk_particles > 0 && o.disk_particles < 1, "disk_particles", o.disk_particles, "in (0, 1)");
}

// The fraction of an untruncated exponential disk's mass inside x = R/h.
double disk_fraction(double x) { return -std::expm1(-x) - x * std::exp(-x); }

// The disk's midplane rotation, V_d²(R) and dV_d²/dR, tabulated once per
// galaxy. A razor-thin exponential disk has V² in closed form (Freeman 1970),
// but the sech² disk's own pull in its midplane is weaker, by 4 % of V_c² at
// h and 2 % at 2h for the default z₀ = h/5 (measured on the particles): a
// disk rotating at the thin disk's speed would start out of balance. So the
// midplane field comes from the Hankel transform of the thick disk (Binney &
// Tremaine 2008, §2.6): with Σ̃(k) = Σ₀h²/(1 + k²h²)^{3/2} the thin disk's
// transform and T(k) = ∫ ρ_z(z) e^{−k|z|} dz / Σ = ∫₀^∞ sech²(u) e^{−kz₀u} du
// the factor of each layer's field reaching z = 0,
//   V_d²(R) = 2πG R ∫₀^∞ k J₁(kR) Σ̃(k) T(k) dk,   dV_d²/dR = 2πG R ∫₀^∞ k² J₀(kR) Σ̃(k) T(k) dk
// (d[R J₁(kR)]/dR = kR J₀(kR)). Simpson's rule on k ∈ [0, 200/h] (the
// integrand falls as k⁻³: the rest is ~10⁻⁵) with 16 points per period of
// J₁(kR) at the disk's edge; R on 32 nodes per e-folding from 10⁻³ h to the
// edge, linear in ln R between them (error ~10⁻⁴). The cut-off of Σ at
// disk_cut·h is left out (it removes (1 + c)e^{−c} of the mass, 5·10⁻⁴ at c = 10).
class DiskRotation {
 public:
  explicit DiskRotation(const DiskGalaxyOptions& o) : h_(o.disk_scale_length), m_(o.disk_mass) {
    const double z0 = o.disk_scale_height, edge = o.disk_cut * h_;
    const double k_max = 200 / h_;
    auto steps = std::size_t(std::ceil(k_max / (2 * kPi / (16 * edge))));
    steps += steps % 2;  // Simpson needs an even count
    const double dk = k_max / double(steps);
    // Σ̃(k)·T(k)·(Simpson weight)·2πG, with Σ₀h² = M_d/2π.
    std::vector<double> k(steps + 1), weight(steps + 1);
    for (std::size_t i = 0; i <= steps; ++i) {
      k[i] = dk * double(i);
      const double simpson = (i == 0 || i == steps ? 1.0 : i % 2 ? 4.0 : 2.0) * dk / 3;
      weight[i] = simpson * m_ * transmission(k[i] * z0) / std::pow(1 + k[i] * k[i] * h_ * h_, 1.5);
    }
    const double lo = std::log(1e-3 * h_), hi = std::log(edge);
    const auto nodes = std::size_t(std::ceil((hi - lo) * 32)) + 1;
    for (std::size_t j = 0; j < nodes; ++j) {
      const double r = std::exp(lo + (hi - lo) * double(j) / double(nodes - 1));
      double v2 = 0, dv2 = 0;
      for (std::size_t i = 1; i <= steps; ++i) {
        // POSIX j0/j1: 20 times faster here than std::cyl_bessel_j.
        const double x = k[i] * r;
        v2 += weight[i] * k[i] * ::j1(x);
        dv2 += weight[i] * k[i] * k[i] * ::j0(x);
      }
      ln_r_.push_back(std::log(r));
      v2_.push_back(r * v2);
      dv2_.push_back(r * dv2);
    }
  }

  // V_d² and dV_d²/dR at R: the table inside its range, the thin disk's closed
  // form outside it (the centre holds 5·10⁻⁷ of the mass, and beyond the edge
  // the thickness no longer matters).
  std::pair<double, double> operator()(double r) const {
    const double u = std::log(r);
    if (u < ln_r_.front() || u > ln_r_.back()) {
      const double d = 1e-4 * r;
      return {thin(r), (thin(r + d) - thin(r - d)) / (2 * d)};
    }
    const std::size_t j = std::min(ln_r_.size() - 1, std::size_t(std::upper_bound(ln_r_.begin(), ln_r_.end(), u) - ln_r_.begin()));
    const double t = (u - ln_r_[j - 1]) / (ln_r_[j] - ln_r_[j - 1]);
    return {v2_[j - 1] + t * (v2_[j] - v2_[j - 1]), dv2_[j - 1] + t * (dv2_[j] - dv2_[j - 1])};
  }

  // Freeman's razor-thin disk: 4πGΣ₀h y² [I₀(y)K₀(y) − I₁(y)K₁(y)], y = R/2h, 4πΣ₀h = 2M_d/h.
  double thin(double r) const {
    const double y = r / (2 * h_);
    return 2 * m_ / h_ * y * y *
           (std::cyl_bessel_i(0.0, y) * std::cyl_bessel_k(0.0, y) - std::cyl_bessel_i(1.0, y) * std::cyl_bessel_k(1.0, y));
  }

 private:
  // T(q) = ∫₀^∞ sech²(u) e^{−qu} du by Simpson's rule on [0, 20] (sech² < 10⁻¹⁶ beyond), 400 intervals.
  static double transmission(double q) {
    constexpr int n = 400;
    constexpr double du = 20.0 / n;
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
      const double u = du * i, c = 1 / std::cosh(u);
      sum += (i == 0 || i == n ? 1.0 : i % 2 ? 4.0 : 2.0) * c * c * std::exp(-q * u);
    }
    return sum * du / 3;
  }

  double h_, m_;
  std::vector<double> ln_r_, v2_, dv2_;
};

// The midplane V_c² (halo + disk) and its radial derivative.
struct Rotation {
  double v2, dv2;
};
Rotation rotation(double r, const DiskGalaxyOptions& o, const DiskRotation& disk) {
  const double mh = 1 - o.disk_mass, a = o.halo_scale_radius;
  // Hernquist: V² = M r/(r + a)², d(V²)/dr = M (a − r)/(r + a)³.
  const auto [v2, dv2] = disk(r);
  return {mh * r / ((r + a) * (r + a)) + v2, mh * (a - r) / std::pow(r + a, 3) + dv2};
}

DiskKinematics kinematics(double r, const DiskGalaxyOptions& o, const DiskRotation& disk) {
  const double h = o.disk_scale_length;
  // The particles carry M_d inside the cut: Σ is the exponential's over the fraction kept.
  const double sigma0 = o.disk_mass / (2 * kPi * h * h * disk_fraction(o.disk_cut));
  const auto surface = [&](double x) { return sigma0 * std::exp(-x / h); };
  const auto kappa2 = [&](double x) {
    const Rotation rot = rotation(x, o, disk);
    return rot.dv2 / x + 2 * rot.v2 / (x * x);
  };
  DiskKinematics k;
  const Rotation rot = rotation(r, o, disk);
  k.circular_speed = std::sqrt(rot.v2);
  k.epicyclic = std::sqrt(kappa2(r));
  k.surface_density = surface(r);
  const double r_ref = kReferenceRadius * h;
  const double sigma_r_ref = o.toomre_q * 3.36 * surface(r_ref) / std::sqrt(kappa2(r_ref));
  k.sigma_r = sigma_r_ref * std::exp(-(r - r_ref) / (2 * h));
  const double omega2 = rot.v2 / (r * r), ratio = k.epicyclic * k.epicyclic / (4 * omega2);
  k.sigma_phi = k.sigma_r * std::sqrt(ratio);
  // The vertical Jeans equation integrated over z (Σσ_z² = ∫ρ z ∂Φ/∂z dz, σ_z independent of z):
  // the sheet's own pull 2πGΣ tanh(z/z₀) gives πGΣz₀ (Hernquist's isothermal sheet), the halo's
  // G M_h(<R) z/R³ (for z ≪ R) adds ⟨z²⟩ G M_h(<R)/R³ with ⟨z²⟩ = π²z₀²/12 for sech². For a
  // light disk the halo's part is not small (75 % of the sheet's at 1.5 h for the default galaxy).
  const double z0 = o.disk_scale_height, a = o.halo_scale_radius, mh = 1 - o.disk_mass;
  const double halo_nu2 = mh / (r * (r + a) * (r + a));  // G M_h(<R)/R³ = M_h/(R (R + a)²)
  k.sigma_z = std::sqrt(kPi * surface(r) * z0 + kPi * kPi / 12 * z0 * z0 * halo_nu2);
  k.mean_rotation = std::sqrt(std::max(0.0, rot.v2 + k.sigma_r * k.sigma_r * (1 - ratio - 2 * r / h)));
  return k;
}

// The halo's tables: its own enclosed mass, the relative potential of halo and
// spherically averaged disk, on 200 nodes per e-folding from 10⁻⁵ a to 10⁵ a.
RadialTable halo_table(const DiskGalaxyOptions& o, std::vector<double>& drho_dpsi) {
  const double mh = 1 - o.disk_mass, md = o.disk_mass, a = o.halo_scale_radius, h = o.disk_scale_length;
  RadialTable t;
  const double lo = 1e-5 * a, hi = 1e5 * a, per_efold = 200;
  const auto n = std::size_t(std::ceil(std::log(hi / lo) * per_efold)) + 1;
  for (std::size_t k = 0; k < n; ++k) t.r.push_back(lo * std::exp(std::log(hi / lo) * double(k) / double(n - 1)));
  const auto disk_mass = [&](double r) { return md * disk_fraction(r / h); };
  // Ψ = M_h/(r + a) + Ψ_disk, Ψ_disk(r) = ∫_r^∞ M_disk(s)/s² ds: the trapezoidal rule in ln s
  // from the last node in, plus M_d/r beyond it (the disk's mass is all inside).
  std::vector<double> disk_psi(n);
  disk_psi[n - 1] = disk_mass(hi) / hi;
  for (std::size_t k = n - 1; k-- > 0;)
    disk_psi[k] = disk_psi[k + 1] + 0.5 * std::log(t.r[k + 1] / t.r[k]) *
                                        (disk_mass(t.r[k + 1]) / t.r[k + 1] + disk_mass(t.r[k]) / t.r[k]);
  drho_dpsi.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double r = t.r[k];
    const double halo_mass = mh * r * r / ((r + a) * (r + a));
    t.mass.push_back(halo_mass);
    t.psi.push_back(mh / (r + a) + disk_psi[k]);
    // dρ/dΨ = ρ′ r²/(−M_total), ρ′ = −ρ (1/r + 3/(r + a)).
    const double rho = mh * a / (2 * kPi * r * std::pow(r + a, 3));
    drho_dpsi[k] = rho * (1 / r + 3 / (r + a)) * r * r / (halo_mass + disk_mass(r));
  }
  return t;
}

// R/h with disk_fraction(x) = f, by bisection on [0, cut] (60 halvings: to 10⁻¹⁷ of the cut).
double disk_radius(double f, double cut) {
  double lo = 0, hi = cut;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (disk_fraction(mid) < f ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

std::vector<DiskKinematics> disk_kinematics(const std::vector<double>& radii, const DiskGalaxyOptions& o) {
  check(o);
  const DiskRotation disk(o);
  std::vector<DiskKinematics> out;
  for (double r : radii) {
    if (!(r > 0 && std::isfinite(r)))
      throw std::invalid_argument(fmt::format("disk_kinematics: radius = {} must be finite and > 0", r));
    out.push_back(kinematics(r, o, disk));
  }
  return out;
}

template <class Real>
ParticleSet<Real> disk_galaxy(std::size_t n, std::uint64_t seed, const DiskGalaxyOptions& o) {
  check(o);
  const auto n_disk = std::size_t(std::llround(o.disk_particles * double(n)));
  if (n_disk == 0 || n_disk >= n)
    throw std::invalid_argument(fmt::format(
        "disk_galaxy: {} particles cannot be split {} : {} with at least one each in the disk and the halo", n,
        o.disk_particles, 1 - o.disk_particles));
  const std::size_t n_halo = n - n_disk;
  std::vector<double> q;
  const RadialTable t = halo_table(o, q);
  const detail::TabulatedDf df = detail::eddington(t, q);
  if (!(detail::most_negative_fraction(df) >= -1e-6))  // NaN too: tables spoilt by extreme scales
    throw std::invalid_argument(fmt::format(
        "disk_galaxy: no isotropic halo is in equilibrium with disk_mass = {}, disk_scale_length = {} and "
        "halo_scale_radius = {} (its distribution function is negative or not finite)",
        o.disk_mass, o.disk_scale_length, o.halo_scale_radius));
  const auto f = [&df](double e) { return df(e); };
  const auto majorant = [&df](double e) { return df.majorant(e); };
  SplitMix64 rng(seed);
  std::vector<V3> x, v;
  std::vector<double> m;
  const double a = o.halo_scale_radius, h = o.disk_scale_length;
  for (std::size_t i = 0; i < n_halo; ++i) {
    // As hernquist(): M(r) = M_h r²/(r + a)² inverted, m > 0 keeps r > 0.
    double u = 0;
    while (!(u > 0)) u = o.halo_mass_cut * rng.uniform();
    const double r = a * std::sqrt(u) / (1 - std::sqrt(u));
    x.push_back(detail::isotropic_vector(rng, r));
    v.push_back(detail::isotropic_vector(rng, detail::sample_speed(rng, t.psi_at(r), f, majorant)));
    m.push_back((1 - o.disk_mass) * o.halo_mass_cut / double(n_halo));
  }
  const double kept = disk_fraction(o.disk_cut);
  const DiskRotation disk(o);
  for (std::size_t i = 0; i < n_disk; ++i) {
    const double r = h * disk_radius(kept * rng.uniform(), o.disk_cut);
    const double phi = 2 * kPi * rng.uniform();
    // sech²(z/z₀) has the cumulative distribution (1 + tanh(z/z₀))/2: z = (z₀/2) ln(u/(1 − u)).
    double u = 0;
    while (!(u > 0)) u = rng.uniform();
    const double z = 0.5 * o.disk_scale_height * std::log(u / (1 - u));
    // R = 0 has no direction to rotate in; the bisection's floor (10⁻¹⁷ h) stands in for it.
    const DiskKinematics k = kinematics(std::max(r, 1e-12 * h), o, disk);
    const double vr = k.sigma_r * detail::normal_deviate(rng);
    const double vphi = k.mean_rotation + k.sigma_phi * detail::normal_deviate(rng);
    const double vz = k.sigma_z * detail::normal_deviate(rng);
    const double c = std::cos(phi), s = std::sin(phi);
    x.push_back({r * c, r * s, z});
    v.push_back({vr * c - vphi * s, vr * s + vphi * c, vz});
    m.push_back(o.disk_mass / double(n_disk));
  }
  // Only the drift is removed: the cusp and the disk's centre stay at the origin.
  double total = 0;
  V3 momentum{};
  for (std::size_t i = 0; i < n; ++i) {
    total += m[i];
    for (std::size_t k = 0; k < 3; ++k) momentum[k] += m[i] * v[i][k];
  }
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < 3; ++k) {
      p.position[int(k)][i] = Real(x[i][k]);
      p.velocity[int(k)][i] = Real(v[i][k] - momentum[k] / total);
    }
    p.mass[i] = Real(m[i]);
    p.id[i] = i;
  }
  return p;
}

template ParticleSet<float> disk_galaxy<float>(std::size_t, std::uint64_t, const DiskGalaxyOptions&);
template ParticleSet<double> disk_galaxy<double>(std::size_t, std::uint64_t, const DiskGalaxyOptions&);

}  // namespace swirl::gravity
