// The particles of the halo tests (tests/dist/halo_test.cpp, sph_halo_test.cpp):
// a jittered lattice block of water, the same bits on every rank, so that each
// rank can build the one-rank reference of the whole set itself.
//
// Initial global order: a fixed permutation of the lattice sites (so the
// first key sort moves nearly every particle); rank r starts with the uneven
// slice [N·r²/s², N·(r+1)²/s²) of it. Velocities: a shear plus noise, so that
// viscosity acts and a step moves particles across the cuts. SI units.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"

namespace swirl::dist::test {

inline constexpr std::uint64_t kNx = 15, kNy = 13, kNz = 12;  // lattice sites per axis
inline constexpr std::uint64_t kParticles = kNx * kNy * kNz;  // 2340
inline constexpr double kSpacing = 0.01;                      // m
inline constexpr double kH = 2.1 * kSpacing;                  // support radius, m (~40 neighbours)
inline constexpr double kRestDensity = 1000;                  // kg/m³

// A number in [0, 1) from (g, salt), the same on every machine.
inline double unit_hash(std::uint64_t g, std::uint64_t salt) {
  std::uint64_t x = (g + 1) * 0x9E3779B97F4A7C15ull + salt * 0xBF58476D1CE4E5B9ull;
  x ^= x >> 31;
  x *= 0x94D049BB133111EBull;
  x ^= x >> 29;
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}

// Fills p[i] with global particle first + i of the initial order.
template <class Real>
void fill_block(ParticleSet<Real>& p, std::uint64_t first, std::uint64_t end) {
  p.resize(end - first);
  for (std::uint64_t g = first; g < end; ++g) {
    const std::size_t i = g - first;
    const std::uint64_t site = g * 7919 % kParticles;  // 7919 is prime and does not divide N
    const std::uint64_t c[3] = {site % kNx, site / kNx % kNy, site / kNx / kNy};
    for (int a = 0; a < 3; ++a)
      p.position[a][i] = Real(kSpacing * (double(c[a]) + 0.35 * (unit_hash(g, std::uint64_t(a)) - 0.5)));
    const double z = double(p.position.z[i]) / (kSpacing * double(kNz)) - 0.5;
    p.velocity.x[i] = Real(0.8 * z + 0.05 * (unit_hash(g, 3) - 0.5));
    p.velocity.y[i] = Real(0.05 * (unit_hash(g, 4) - 0.5));
    p.velocity.z[i] = Real(-0.3 + 0.05 * (unit_hash(g, 5) - 0.5));
    p.mass[i] = Real(kRestDensity * kSpacing * kSpacing * kSpacing * (0.98 + 0.04 * unit_hash(g, 6)));
    p.id[i] = g;
  }
}

// The same particles scattered at random over a cube of side 24 h instead
// (one particle per six cells): many cells with no neighbour occupied, where a ghost
// search that skipped some of the 27 cells would show.
template <class Real>
void scatter(ParticleSet<Real>& p, std::uint64_t first) {
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 3; ++a) p.position[a][i] = Real(24 * kH * unit_hash(first + i, 10 + std::uint64_t(a)));
}

// This rank's uneven initial slice [first, end) of the initial order.
struct Slice {
  std::uint64_t first = 0, end = 0;
};
inline Slice initial_slice(const Communicator& comm) {
  const auto s = static_cast<std::uint64_t>(comm.size()), r = static_cast<std::uint64_t>(comm.rank());
  return {kParticles * r * r / (s * s), kParticles * (r + 1) * (r + 1) / (s * s)};
}

// One drift x += v·dt of particles [b, e), dt = 2⁻⁶ s (about one spacing at
// the largest speed): a power of two, so v·dt is exact and x + v·dt is one
// rounding whether or not the compiler fuses it: the ranks' slices and the
// one-rank reference get the same bits.
template <class Real>
void drift(ParticleSet<Real>& p, std::size_t b, std::size_t e) {
  const Real dt = Real(0.015625);
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = b; i < e; ++i) p.position[a][i] += p.velocity[a][i] * dt;
}

}  // namespace swirl::dist::test
