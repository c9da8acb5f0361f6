// The stable time step of a particle state: the conditions an explicit step
// must satisfy, evaluated from the particle fields and the solvers' parameters.
//
// SPH (h is the kernel support radius, as everywhere in swirl; c the sound
// speed; μ the dynamic viscosity; SI units):
//   CFL       Δt ≤ C_cfl · h / (c + |v|max)           (Monaghan 1992)
//   force     Δt ≤ C_force · sqrt(h / |a|max)          (Monaghan 1992)
//   viscous   Δt ≤ C_visc · h² · ρ_min / μ             (Morris et al. 1997: h²/ν with ν = μ/ρ)
// Gravity (G = 1 units; ε the Plummer softening):
//   ε > 0     Δt ≤ η · sqrt(ε / |a|max)
//   ε = 0     Δt ≤ η · sqrt(d / |a|max), with d = L / N^(1/3) the mean particle
//             separation of the system (L the largest extent of the particles'
//             bounding box): without softening the smallest length the forces
//             resolve is the spacing of the particles themselves.
// |a| is the total acceleration (every force model), |v| the speed.
//
// A state is scanned once per step, fused into the velocity update
// (scan_block), and the per-block results are folded in block order through
// parallel::reduce_blocks (combine), so the limits, and an adaptive step
// chosen from them, are bit-identical for any thread count. Ties keep the
// lowest particle index.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string_view>

#include "swirl/core/particle_set.hpp"
#include "swirl/core/vec3.hpp"

namespace swirl::sim {

inline constexpr std::size_t kNoParticle = std::numeric_limits<std::size_t>::max();

// The constants of the SPH conditions; defaults are the usual ones.
struct SphStepLimits {
  double smoothing_length = 0;   // h, m (> 0)
  double sound_speed = 0;        // c, m/s (> 0)
  double viscosity = 0;          // μ, Pa·s (≥ 0; 0 switches the viscous condition off)
  double cfl = 0.6;              // C_cfl
  double force_factor = 0.4;     // C_force
  double viscous_factor = 0.125; // C_visc
};

// The constant of the gravity condition.
struct GravityStepLimits {
  double softening = 0;  // ε, length units (≥ 0)
  double eta = 0.75;     // η
};

// What limits the step of a simulation; neither: no condition (Δt is free).
struct StepLimitSettings {
  std::optional<SphStepLimits> sph;
  std::optional<GravityStepLimits> gravity;
};

// Per-block (and, folded, global) extremes of a state.
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
// the extremes the conditions need. Reads only. The common case (all finite)
// costs one vectorised pass per field and per extreme; the particle indices
// are searched for only in this block, once its extremes are known.
template <class Real>
StepScan scan_block(const ParticleSet<Real>& p, std::size_t begin, std::size_t end, bool want_density,
                    bool want_bounds) {
  StepScan s;
  // x·0 is 0 for finite x and NaN otherwise, so a plain sum finds any NaN or infinity.
  for (const auto& f : p.fields()) {
    for (int c = 0; c < f.components; ++c) {
      const Real* x = f.data[static_cast<std::size_t>(c)];
      Real poison = 0;
#pragma omp simd reduction(+ : poison)
      for (std::size_t i = begin; i < end; ++i) poison += x[i] * Real(0);
      if (poison == Real(0)) continue;
      for (std::size_t i = begin; i < std::min(end, s.non_finite); ++i)
        if (!std::isfinite(x[i])) {
          s.non_finite = i;
          break;
        }
    }
  }
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
  if (want_density) {
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
  if (want_bounds) {
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

// One condition's limit on the step.
struct StepLimit {
  std::string_view condition;       // "cfl", "force", "viscous", "gravity"; empty: no condition
  double dt = std::numeric_limits<double>::infinity();  // the largest stable step
  std::size_t particle = kNoParticle;  // index of the particle that sets it
  double value = 0;                 // its |v|, |a| or ρ
};

// The limits of a scanned state: every condition, and the smallest.
struct StepLimits {
  StepLimit cfl, force, viscous, gravity;
  const StepLimit& tightest() const {
    const StepLimit* best = &cfl;
    for (const StepLimit* l : {&force, &viscous, &gravity})
      if (l->dt < best->dt) best = l;
    return *best;
  }
};

// Evaluates the conditions (header comment) for a scanned state of n particles.
inline StepLimits evaluate_limits(const StepScan& scan, const StepLimitSettings& settings, std::size_t n) {
  StepLimits out;
  const double speed = std::sqrt(scan.speed2), accel = std::sqrt(scan.accel2);
  if (const auto& s = settings.sph) {
    const double h = s->smoothing_length;
    out.cfl = {"cfl", s->cfl * h / (s->sound_speed + speed), scan.speed_at, speed};
    if (accel > 0) out.force = {"force", s->force_factor * std::sqrt(h / accel), scan.accel_at, accel};
    if (s->viscosity > 0 && scan.density_at != kNoParticle)
      out.viscous = {"viscous", s->viscous_factor * h * h * scan.density / s->viscosity, scan.density_at, scan.density};
  }
  if (const auto& g = settings.gravity) {
    double length = g->softening;
    if (!(length > 0) && n > 1) {
      double extent = 0;
      for (int axis = 0; axis < 3; ++axis) extent = std::max(extent, scan.hi[axis] - scan.lo[axis]);
      length = extent / std::cbrt(static_cast<double>(n));
    }
    if (accel > 0 && length > 0) out.gravity = {"gravity", g->eta * std::sqrt(length / accel), scan.accel_at, accel};
  }
  return out;
}

}  // namespace swirl::sim
