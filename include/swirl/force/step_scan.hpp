// The scan of a particle state that every step makes once, fused into the
// stepper's last pass: non-finite fields, and the extremes that the solvers'
// time-step conditions need (|v|max, |a|max, ρ_min, the bounding box).
//
// Each solver states what it needs (ScanNeeds) and turns the folded scan into
// its StepLimits (force/solver.hpp); the scan itself knows no solver.
//
// Determinism: scan_block() covers one work block; blocks are folded in block
// order with StepScan::combine (parallel::reduce_blocks), so the scan, the
// limits and an adaptive step chosen from them are bit-identical for any
// thread count. Ties keep the lowest particle index.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string_view>

#include "swirl/core/particle_set.hpp"
#include "swirl/core/vec3.hpp"

namespace swirl {

inline constexpr std::size_t kNoParticle = std::numeric_limits<std::size_t>::max();

// What the scan must measure beyond |v|max and |a|max (always measured).
struct ScanNeeds {
  bool min_density = false;  // ρ_min and where (an SPH viscous condition)
  bool bounds = false;       // the particles' bounding box (gravity without softening)

  ScanNeeds& operator|=(const ScanNeeds& o) {
    min_density |= o.min_density;
    bounds |= o.bounds;
    return *this;
  }
};

// Per-block (and, folded, global) extremes of a state. Indices are storage indices.
struct StepScan {
  std::size_t non_finite = kNoParticle;  // first particle with a non-finite field
  double speed2 = 0;                     // max |v|²
  std::size_t speed_at = kNoParticle;
  double accel2 = 0;                     // max |a|²
  std::size_t accel_at = kNoParticle;
  double density = std::numeric_limits<double>::infinity();  // min ρ (only when asked)
  std::size_t density_at = kNoParticle;
  Vec3d lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity()};
  Vec3d hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
           -std::numeric_limits<double>::infinity()};  // bounding box (only when asked)

  // Folds b (a later block) into a: b wins only strictly, so ties keep the lower index.
  static StepScan combine(StepScan a, const StepScan& b) {
    a.non_finite = std::min(a.non_finite, b.non_finite);
    if (b.speed2 > a.speed2) a.speed2 = b.speed2, a.speed_at = b.speed_at;
    if (b.accel2 > a.accel2) a.accel2 = b.accel2, a.accel_at = b.accel_at;
    if (b.density < a.density) a.density = b.density, a.density_at = b.density_at;
    for (int axis = 0; axis < 3; ++axis) {
      a.lo[axis] = std::min(a.lo[axis], b.lo[axis]);
      a.hi[axis] = std::max(a.hi[axis], b.hi[axis]);
    }
    return a;
  }
};

// Scans particles [begin, end): every real field for non-finite values, and
// the extremes asked for. Reads only. The common case (all finite) costs one
// vectorised pass per field and per extreme; the particle indices are
// searched for only in this block, once its extremes are known.
template <class Real>
StepScan scan_block(const ParticleSet<Real>& p, std::size_t begin, std::size_t end, const ScanNeeds& needs) {
  StepScan s;
  // x·0 is 0 for finite x and NaN otherwise, so a plain sum finds any NaN or infinity.
  p.for_each_array([&](const AlignedVector<Real>& field) {
    const Real* x = field.data();
    Real poison = 0;
#pragma omp simd reduction(+ : poison)
    for (std::size_t i = begin; i < end; ++i) poison += x[i] * Real(0);
    if (poison == Real(0)) return;
    for (std::size_t i = begin; i < std::min(end, s.non_finite); ++i)
      if (!std::isfinite(x[i])) {
        s.non_finite = i;
        break;
      }
  });
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  const Real *ax = p.acceleration.x.data(), *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
  // In Real: twice the vector width of double for float, and precise enough for a limit.
  auto norm2 = [](const Real* x, const Real* y, const Real* z, std::size_t i) {
    return x[i] * x[i] + y[i] * y[i] + z[i] * z[i];
  };
  Real v2 = 0, a2 = 0;
#pragma omp simd reduction(max : v2, a2)
  for (std::size_t i = begin; i < end; ++i) {
    v2 = std::max(v2, norm2(vx, vy, vz, i));
    a2 = std::max(a2, norm2(ax, ay, az, i));
  }
  // The first particle with the block's extreme (none when it is 0 or NaN).
  auto first_with = [&](const Real* x, const Real* y, const Real* z, Real m) {
    if (!(m > 0)) return kNoParticle;
    for (std::size_t i = begin; i < end; ++i)
      if (norm2(x, y, z, i) == m) return i;
    return kNoParticle;
  };
  s.speed2 = v2 > 0 ? double(v2) : 0;
  s.speed_at = first_with(vx, vy, vz, v2);
  s.accel2 = a2 > 0 ? double(a2) : 0;
  s.accel_at = first_with(ax, ay, az, a2);
  if (needs.min_density) {
    const Real* rho = p.density.data();
    Real lowest = std::numeric_limits<Real>::infinity();
#pragma omp simd reduction(min : lowest)
    for (std::size_t i = begin; i < end; ++i) lowest = std::min(lowest, rho[i]);
    for (std::size_t i = begin; i < end; ++i)
      if (rho[i] == lowest) {
        s.density = double(lowest), s.density_at = i;
        break;
      }
  }
  if (needs.bounds) {
    for (int axis = 0; axis < 3; ++axis) {
      const Real* x = p.position[axis].data();
      Real lo = std::numeric_limits<Real>::infinity(), hi = -std::numeric_limits<Real>::infinity();
#pragma omp simd reduction(min : lo) reduction(max : hi)
      for (std::size_t i = begin; i < end; ++i) {
        lo = std::min(lo, x[i]);
        hi = std::max(hi, x[i]);
      }
      s.lo[axis] = double(lo);
      s.hi[axis] = double(hi);
    }
  }
  return s;
}

// One condition's limit on the step, made by a solver from a scan.
struct StepLimit {
  std::string_view condition;      // e.g. "cfl", "force", "viscous", "gravity"; empty: no condition
  double dt = std::numeric_limits<double>::infinity();  // the largest stable step
  std::size_t particle = kNoParticle;  // storage index of the particle that sets it
  double value = 0;                // its |v|, |a| or ρ
  std::string_view quantity;       // what `value` is: "|v|", "|a|", "ρ"
  std::size_t source = 0;          // which solver made it (the simulation's index), for its message
};

}  // namespace swirl
