// The gather passes of divergence-free SPH (Bender & Koschier, "Divergence-
// free smoothed particle hydrodynamics", SCA 2015, and "Divergence-free SPH
// for incompressible and viscous fluids", TVCG 2017), over the sorted cell
// grid the SPH solver already builds (spatial/cell_grid.hpp, no second search):
//
//   dfsph_density_and_factor   ρ_i = Σ_j m_j W_ij (i itself included) and the
//                              DFSPH factor (2017, eq. 10 and 11)
//                                α_i = ρ_i / (|Σ_j m_j ∇W_ij|² + Σ_j |m_j ∇W_ij|²)
//                              (α_i = 0 where the denominator vanishes: an
//                              isolated particle, which no pressure can help;
//                              and at most a cap, SphFluid's twice the factor
//                              of a full lattice: a splash pair near r = h has
//                              |∇W| → 0 and α ∝ 1/|∇W|², and one Jacobi step
//                              with it overshoots. Uncapped, the dam break with
//                              an adaptive step blew up at t = 0.53 s with
//                              |v| = 5e5 m/s; capped it runs to 1.5 s. Ours.)
//   dfsph_density_change       (Dρ/Dt)_i = Σ_j m_j (v_i − v_j)·∇W_ij   (2017, eq. 7)
//   dfsph_pressure_velocity    v_i ← v_i − Δt Σ_j m_j (k_i + k_j) ∇W_ij,
//                              k = κ/ρ (2017, eq. 12 and 14: the velocity
//                              change of the pressure force −Σ_j m_j (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij)
//   dfsph_add_viscosity        a_i += μ/ρ_i Σ_j V_j (v_j − v_i) ∇²W_visc(r_ij),
//                              the thesis's viscosity term (eq. 2.10) as the
//                              non-pressure force
//   dfsph_xsph_change          Δv_i = ε Σ_j 2m_j/(ρ_i + ρ_j) (v_j − v_i) W_ij,
//                              the XSPH filter (sph.xsph), fluid j only
//   dfsph_surface_normals      n_i = h Σ_j (m_j/ρ_j) ∇W_ij (Akinci et al. 2013)
//   dfsph_add_surface_forces   Akinci et al. 2013's cohesion, curvature and
//                              adhesion (sph.surface_tension, sph.adhesion)
//
// Boundary particles (Akinci et al. 2012; core/particle_kind.hpp): with a
// `kind` array (null: all fluid), a boundary particle b carries its volume
// weight ψ_b = ρ0 / Σ_k W_bk in its mass, so the sums over j above take it as
// one more neighbour of mass ψ_b moving with its velocity v_b (0 for a static
// wall, the prescribed one for a moving obstacle); its own κ stays 0, so the
// pressure term of a pair (i, b) is ψ_b (κ_i/ρ_i) ∇W_ib, the fluid particle's
// own term (the pressure mirrored onto the wall). In α's second sum only
// fluid neighbours count (a boundary particle has no κ of its own to solve
// for). A boundary particle itself is skipped: ρ_b = ρ0, α_b = 0, Dρ/Dt = 0,
// its velocity and acceleration untouched.
//
// `only` (every pass): computes the particles [only.begin, only.end) alone,
// reading the others as neighbours (a rank's own particles among its ghosts,
// dist/halo.hpp); each particle's result is the bits of a pass over all.
//
// Scalar loops, one pair at a time. The solves run dfsph_density_change and
// dfsph_pressure_velocity over the pairs the density pass kept
// (sph/dfsph_pairs.hpp); the grid versions here are their slow twins, and
// both write their multiply-adds as sph/dfsph_terms.hpp's (the same bits).
// Each pass writes only particle i's entries and gathers over the grid's fixed
// candidate ranges, so its result is bit-identical for any thread count.
// Units: SI (ρ in kg/m³, κ in m²/s², α in m⁶·s⁰/kg: ρ/(kg²/m⁸)).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "swirl/core/index_range.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/distance.hpp"
#include "swirl/sph/dfsph_pairs.hpp"
#include "swirl/sph/dfsph_terms.hpp"
#include "swirl/sph/grid_passes.hpp"
#include "swirl/sph/kernels.hpp"
#include "swirl/sph/laws.hpp"

namespace swirl::sph {

namespace detail {

// Calls pair(j, dx, dy, dz, r) for every j with r_ij² < h² (i itself included,
// r = 0), in the grid's candidate order.
template <class Real, class Pair>
inline void for_each_pair(const Real* x, const Real* y, const Real* z, std::size_t i,
                          const spatial::NeighbourRanges& ranges, int count, Real h2, Pair&& pair) {
  for (int r = 0; r < count; ++r)
    for (std::size_t j = ranges[static_cast<std::size_t>(r)].begin; j < ranges[static_cast<std::size_t>(r)].end; ++j) {
      const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const Real r2 = dx * dx + dy * dy + dz * dz;
      if (!spatial::within(r2, h2)) continue;
      pair(j, dx, dy, dz, r2);
    }
}

// The particles a pass computes: `only`, or all of them when only is kAllParticles.
inline constexpr IndexRange kAllParticles{0, ~std::uint32_t{0}};
inline IndexRange pass_range(IndexRange only, std::size_t n) {
  if (only.begin == kAllParticles.begin && only.end == kAllParticles.end) return {0, static_cast<std::uint32_t>(n)};
  check_range(only, n);
  return only;
}

}  // namespace detail

// The factor of a particle inside a simple cubic lattice of spacing s with
// particles of mass m (there Σ_j m_j ∇W_ij = 0): ρ0 / Σ_j |m ∇W_ij|², ρ0 = m/s³.
template <class Real>
double dfsph_lattice_factor(const DfsphKernel<Real>& kernel, double m, double s) {
  // No fluid yet (a scene whose fluid comes from inlets): no lattice, no factor.
  if (!(m > 0) || !(s > 0)) return 0.0;
  const int reach = static_cast<int>(std::ceil(double(kernel.h) / s));
  double sum = 0;
  for (int a = -reach; a <= reach; ++a)
    for (int b = -reach; b <= reach; ++b)
      for (int c = -reach; c <= reach; ++c) {
        const double r = s * std::sqrt(double(a * a + b * b + c * c));
        if (r >= double(kernel.h)) continue;
        const double g = m * double(kernel.gradient(Real(r))) * r;  // |m ∇W|
        sum += g * g;
      }
  return sum > 0 ? m / (s * s * s) / sum : 0.0;
}

// ρ into p.density, α into alpha[0, n), α at most alpha_cap; returns the
// neighbour pairs (self excluded). kind: null, or the particles' kinds (then
// a boundary particle gets ρ = rest_density and α = 0). keep: null, or where
// the pairs found and their ∇W radial factors are kept for the solves
// (sph/dfsph_pairs.hpp).
template <class Real>
std::uint64_t dfsph_density_and_factor(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                                       const DfsphKernel<Real>& kernel, std::size_t block_size, Real* alpha,
                                       Real alpha_cap, const std::int32_t* kind = nullptr, Real rest_density = 0,
                                       IndexRange only = detail::kAllParticles, DfsphPairs<Real>* keep = nullptr) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  Real* rho = p.density.data();
  if (keep) keep->prepare(range, block_size);
  return parallel::reduce_blocks_pinned(
      "dfsph_density", range.end - range.begin, block_size, std::uint64_t{0},
      [&](std::size_t b, std::size_t e) {
        const DfsphKernel<Real> k = kernel;
        std::uint64_t pairs = 0;
        typename DfsphPairs<Real>::Block* list = keep ? &keep->start_block(b) : nullptr;
        detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
          if (kind && is_boundary(kind[i])) {
            rho[i] = rest_density;
            alpha[i] = 0;
            if (list) keep->end_list(i - from, list->size());
            return;
          }
          Real density = 0, gx = 0, gy = 0, gz = 0, g2 = 0;
          std::uint64_t found = 0;
          detail::for_each_pair(x, y, z, i, ranges, count, k.h2, [&](std::size_t j, Real dx, Real dy, Real dz, Real r2) {
            const Real r = std::sqrt(r2);
            density += m[j] * k.w(r2, r);
            ++found;
            const Real gradient = k.gradient(r);
            const Real g = m[j] * gradient;  // m_j ∇W_ij = g · r⃗_ij (0 for j = i)
            gx += g * dx, gy += g * dy, gz += g * dz;
            if (!kind || !is_boundary(kind[j])) g2 += g * g * r2;
            if (list && j != i) list->push_back(static_cast<std::uint32_t>(j), gradient);
          });
          if (list) keep->end_list(i - from, list->size());
          rho[i] = density;
          const Real denominator = gx * gx + gy * gy + gz * gz + g2;
          // The floor: a millionth of one neighbour's |m ∇W|² at the kernel's
          // steepest scale (m/h⁴)²; below it the particle has (nearly) no
          // neighbours and no pressure can change its density.
          const Real scale = m[i] / (k.h2 * k.h2);
          alpha[i] = denominator > Real(1e-6) * scale * scale ? std::min(density / denominator, alpha_cap) : Real(0);
          pairs += found - 1;
        });
        return pairs;
      },
      [](std::uint64_t a, std::uint64_t b) { return a + b; });
}

// out[i] = (Dρ/Dt)_i from the current velocities (0 for a boundary particle).
template <class Real>
void dfsph_density_change(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& p,
                          const DfsphKernel<Real>& kernel, std::size_t block_size, Real* out,
                          const std::int32_t* kind = nullptr, IndexRange only = detail::kAllParticles) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  parallel::for_blocks_pinned("dfsph_density_change", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const DfsphKernel<Real> k = kernel;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      if (kind && is_boundary(kind[i])) {
        out[i] = 0;
        return;
      }
      Real sum = 0;
      detail::for_each_pair(x, y, z, i, ranges, count, k.h2, [&](std::size_t j, Real dx, Real dy, Real dz, Real r2) {
        const Real g = m[j] * k.gradient(std::sqrt(r2));
        sum = detail::density_change_term(sum, g, vx[i] - vx[j], vy[i] - vy[j], vz[i] - vz[j], dx, dy, dz);
      });
      out[i] = sum;
    });
  });
}

// v_i −= Δt Σ_j m_j (k_i + k_j) ∇W_ij, k = κ/ρ per particle (0 for a boundary
// particle, whose velocity is left alone). Reads no velocity, so writing v_i
// in place is safe.
template <class Real>
void dfsph_pressure_velocity(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                             const DfsphKernel<Real>& kernel, std::size_t block_size, const Real* k_over_rho, Real dt,
                             const std::int32_t* kind = nullptr, IndexRange only = detail::kAllParticles) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data();
  parallel::for_blocks_pinned("dfsph_pressure", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const DfsphKernel<Real> k = kernel;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      if (kind && is_boundary(kind[i])) return;
      Real ax = 0, ay = 0, az = 0;
      const Real ki = k_over_rho[i];
      detail::for_each_pair(x, y, z, i, ranges, count, k.h2, [&](std::size_t j, Real dx, Real dy, Real dz, Real r2) {
        const Real g = m[j] * (ki + k_over_rho[j]) * k.gradient(std::sqrt(r2));
        ax = detail::fused(g, dx, ax), ay = detail::fused(g, dy, ay), az = detail::fused(g, dz, az);
      });
      vx[i] = detail::fused(-dt, ax, vx[i]);
      vy[i] = detail::fused(-dt, ay, vy[i]);
      vz[i] = detail::fused(-dt, az, vz[i]);
    });
  });
}

// a_i += the thesis's viscous acceleration (eq. 2.10 / ρ_i, laws.viscosity).
template <class Real>
void dfsph_add_viscosity(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p, const SphLaws<Real>& laws,
                         std::size_t block_size, const std::int32_t* kind = nullptr,
                         IndexRange only = detail::kAllParticles) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data(), *rho = p.density.data();
  Real *ax = p.acceleration.x.data(), *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
  parallel::for_blocks_pinned("dfsph_viscosity", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const SphLaws<Real> law = laws;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      if (kind && is_boundary(kind[i])) return;  // static: its acceleration is zeroed anyway
      Real sx = 0, sy = 0, sz = 0;
      detail::for_each_pair(x, y, z, i, ranges, count, law.h2, [&](std::size_t j, Real, Real, Real, Real r2) {
        const Real t = law.viscosity.term(m[j] / rho[j], law.gap(std::sqrt(r2)));
        sx += t * (vx[j] - vx[i]), sy += t * (vy[j] - vy[i]), sz += t * (vz[j] - vz[i]);
      });
      const Real f = law.viscosity.norm / rho[i];
      ax[i] += f * sx;
      ay[i] += f * sy;
      az[i] += f * sz;
    });
  });
}

// XSPH's velocity change (Monaghan 1989's filter, symmetrised):
//   Δv_i = ε Σ_j 2 m_j / (ρ_i + ρ_j) · (v_j − v_i) W_ij       (fluid j only)
// into dv[0..2][i] (0 for a boundary particle). Its pair terms times m_i are
// antisymmetric, so Σ_i m_i Δv_i = 0: applied to every particle at once (the
// caller adds dv after the pass) it conserves linear momentum to rounding.
template <class Real>
void dfsph_xsph_change(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& p,
                       const DfsphKernel<Real>& kernel, std::size_t block_size, Real epsilon, Real* const dv[3],
                       const std::int32_t* kind = nullptr, IndexRange only = detail::kAllParticles) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  const Real *vx = p.velocity.x.data(), *vy = p.velocity.y.data(), *vz = p.velocity.z.data(), *rho = p.density.data();
  parallel::for_blocks_pinned("dfsph_xsph", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const DfsphKernel<Real> k = kernel;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      Real sx = 0, sy = 0, sz = 0;
      if (!kind || !is_boundary(kind[i]))
        detail::for_each_pair(x, y, z, i, ranges, count, k.h2, [&](std::size_t j, Real, Real, Real, Real r2) {
          if (kind && is_boundary(kind[j])) return;
          const Real t = Real(2) * m[j] / (rho[i] + rho[j]) * k.w(r2, std::sqrt(r2));
          sx += t * (vx[j] - vx[i]), sy += t * (vy[j] - vy[i]), sz += t * (vz[j] - vz[i]);
        });
      dv[0][i] = epsilon * sx;
      dv[1][i] = epsilon * sy;
      dv[2][i] = epsilon * sz;
    });
  });
}

// Akinci et al. 2013's surface normals (eq. 4), dimensionless:
//   n_i = h Σ_j (m_j/ρ_j) ∇W_ij      (fluid j only; 0 for a boundary particle)
// |n| grows from 0 inside the fluid to about 1 at a free surface, pointing out.
template <class Real>
void dfsph_surface_normals(const spatial::SortedCellGrid<Real>& grid, const ParticleSet<Real>& p,
                           const DfsphKernel<Real>& kernel, std::size_t block_size, Real* const n[3],
                           const std::int32_t* kind = nullptr, IndexRange only = detail::kAllParticles) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  const Real* rho = p.density.data();
  parallel::for_blocks_pinned("dfsph_normals", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const DfsphKernel<Real> k = kernel;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      Real sx = 0, sy = 0, sz = 0;
      if (!kind || !is_boundary(kind[i]))
        detail::for_each_pair(x, y, z, i, ranges, count, k.h2, [&](std::size_t j, Real dx, Real dy, Real dz, Real r2) {
          if (kind && is_boundary(kind[j])) return;
          const Real g = m[j] / rho[j] * k.gradient(std::sqrt(r2));
          sx += g * dx, sy += g * dy, sz += g * dz;
        });
      n[0][i] = k.h * sx;
      n[1][i] = k.h * sy;
      n[2][i] = k.h * sz;
    });
  });
}

// Akinci et al. 2013's surface tension and adhesion as accelerations, added
// into a_i of every fluid particle (x̂_ij = r⃗_ij/r, r⃗_ij = x_i − x_j):
//   fluid j ≠ i:  a_i += −γ K_ij (m_j C(r) x̂_ij + (n_i − n_j)),  K_ij = 2ρ0/(ρ_i + ρ_j)   (eq. 1–5)
//   boundary b:   a_i += −β ψ_b A(r) x̂_ib                                                (eq. 6)
// C, A: sph/kernels.hpp's Akinci splines; n: dfsph_surface_normals(); ψ_b:
// the boundary particle's volume weight ρ0 V_b (its mass field). The pair
// terms times m_i are antisymmetric between fluid particles.
template <class Real>
void dfsph_add_surface_forces(const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                              const DfsphKernel<Real>& kernel, std::size_t block_size, Real gamma, Real beta,
                              Real rest_density, const Real* const n[3], const std::int32_t* kind = nullptr,
                              IndexRange only = detail::kAllParticles) {
  const IndexRange range = detail::pass_range(only, p.size());
  const std::size_t from = range.begin;
  const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data(), *m = p.mass.data();
  const Real* rho = p.density.data();
  Real *ax = p.acceleration.x.data(), *ay = p.acceleration.y.data(), *az = p.acceleration.z.data();
  const Real *nx = n[0], *ny = n[1], *nz = n[2];
  const AkinciCohesion<Real> cohesion(kernel.h);
  const AkinciAdhesion<Real> adhesion(kernel.h);
  parallel::for_blocks_pinned("dfsph_surface", range.end - range.begin, block_size,
                              [&](std::size_t b, std::size_t e, std::size_t) {
    const Real h2 = kernel.h2, two_rho0 = Real(2) * rest_density;
    detail::for_each_in_cells(grid, from + b, from + e, [&](std::size_t i, const auto& ranges, int count) {
      if (kind && is_boundary(kind[i])) return;  // static: its acceleration is zeroed anyway
      Real sx = 0, sy = 0, sz = 0;  // Σ over fluid j of K_ij (…), times −γ below
      Real tx = 0, ty = 0, tz = 0;  // Σ over boundary b of ψ_b A(r) x̂, times −β below
      detail::for_each_pair(x, y, z, i, ranges, count, h2, [&](std::size_t j, Real dx, Real dy, Real dz, Real r2) {
        if (j == i) return;
        const Real r = std::sqrt(r2), inv_r = r > Real(0) ? Real(1) / r : Real(0);
        if (kind && is_boundary(kind[j])) {
          const Real t = m[j] * adhesion(r) * inv_r;
          tx += t * dx, ty += t * dy, tz += t * dz;
          return;
        }
        if (gamma == Real(0)) return;  // adhesion only: n is not computed
        const Real K = two_rho0 / (rho[i] + rho[j]), c = m[j] * cohesion(r) * inv_r;
        sx += K * (c * dx + (nx[i] - nx[j]));
        sy += K * (c * dy + (ny[i] - ny[j]));
        sz += K * (c * dz + (nz[i] - nz[j]));
      });
      ax[i] -= gamma * sx + beta * tx;
      ay[i] -= gamma * sy + beta * ty;
      az[i] -= gamma * sz + beta * tz;
    });
  });
}

}  // namespace swirl::sph
