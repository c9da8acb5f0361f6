// Helpers shared by the gravity tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/settings.hpp"

namespace swirl::gravity::testing {

using Precisions = ::testing::Types<float, double>;
inline constexpr std::array<Scheme, 3> kSchemes{Scheme::Subdomain, Scheme::Subtree, Scheme::Global};

template <class Real>
ParticleSet<double> to_double(const ParticleSet<Real>& p) {
  ParticleSet<double> d(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      d.position[a][i] = p.position[a][i];
      d.velocity[a][i] = p.velocity[a][i];
    }
    d.mass[i] = p.mass[i];
    d.id[i] = p.id[i];
  }
  return d;
}

template <class Real>
GravityField<Real> tree_field(const ParticleSet<Real>& p, const GravitySettings& s, std::size_t block_size = 64) {
  BarnesHut<Real> tree(s);
  GravityField<Real> f;
  tree.compute(p, f, block_size);
  return f;
}

// |a − b| / |ref| for every particle, sorted ascending.
template <class A, class B>
std::vector<double> relative_errors(const GravityField<A>& a, const GravityField<B>& b, const GravityField<double>& ref) {
  std::vector<double> e(ref.size());
  for (std::size_t i = 0; i < e.size(); ++i) {
    double d2 = 0, r2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = double(a.acceleration[k][i]) - double(b.acceleration[k][i]);
      d2 += d * d;
      r2 += ref.acceleration[k][i] * ref.acceleration[k][i];
    }
    e[i] = std::sqrt(d2 / r2);
  }
  std::sort(e.begin(), e.end());
  return e;
}

inline double quantile(const std::vector<double>& sorted, double q) {
  return sorted[std::size_t(q * double(sorted.size() - 1))];
}

// Every real field and the ids have the same bits.
template <class Real>
bool same_bits(const ParticleSet<Real>& a, const ParticleSet<Real>& b) {
  const auto fa = a.fields(), fb = b.fields();
  if (fa.size() != fb.size() || a.size() != b.size()) return false;
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      if (std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(Real)) != 0) return false;
  return a.id == b.id;
}

template <class Real>
bool same_bits(const GravityField<Real>& a, const GravityField<Real>& b) {
  const std::size_t bytes = a.size() * sizeof(Real);
  return a.size() == b.size() && std::memcmp(a.acceleration.x.data(), b.acceleration.x.data(), bytes) == 0 &&
         std::memcmp(a.acceleration.y.data(), b.acceleration.y.data(), bytes) == 0 &&
         std::memcmp(a.acceleration.z.data(), b.acceleration.z.data(), bytes) == 0 &&
         std::memcmp(a.potential.data(), b.potential.data(), bytes) == 0;
}

}  // namespace swirl::gravity::testing
