// The interaction kernels' scalar reference and the dispatch of the SIMD path
// to the copy of interaction_kernels_simd.cpp for the active instruction set.
#include "swirl/gravity/interaction_kernels.hpp"

#include <cmath>

#include "swirl/core/simd_dispatch.hpp"
#include "swirl/gravity/pair_law.hpp"

namespace swirl::gravity {

// The SIMD copies (interaction_kernels_simd.cpp, one per instruction set).
#define SWIRL_DECLARE_INTERACTION_KERNELS(isa)                                                                  \
  namespace isa {                                                                                              \
  void particle_field(const SourceParticles<float>& s, const Targets<float>& t, float eps2);                   \
  void particle_field(const SourceParticles<double>& s, const Targets<double>& t, double eps2);                \
  void cell_field(const SourceCells<float>& s, const Targets<float>& t, float eps2, bool quadrupole);          \
  void cell_field(const SourceCells<double>& s, const Targets<double>& t, double eps2, bool quadrupole);       \
  }
SWIRL_SIMD_FOR_EACH_NS(SWIRL_DECLARE_INTERACTION_KERNELS)
#undef SWIRL_DECLARE_INTERACTION_KERNELS

namespace {

template <class Real>
void particle_field_scalar(const SourceParticles<Real>& s, const Targets<Real>& t, Real eps2) {
  for (std::size_t i = 0; i < t.n; ++i) {
    const Real tx = t.x[i], ty = t.y[i], tz = t.z[i];
    // The source that is this target, if any.
    const std::size_t self =
        s.self_offset == SourceParticles<Real>::npos ? SourceParticles<Real>::npos : s.self_offset + i;
    Accumulator<Real> acc;
    for (std::size_t j = 0; j < s.n; ++j) {
      if (j == self) continue;
      acc.add(s.x[j] - tx, s.y[j] - ty, s.z[j] - tz, s.m[j], eps2);
    }
    t.ax[i] += acc.ax;
    t.ay[i] += acc.ay;
    t.az[i] += acc.az;
    t.phi[i] += acc.phi;
  }
}

// law(j, dx, dy, dz, inv, acc) adds cell j's term to acc.
template <class Real, class Law>
void cells_scalar(const SourceCells<Real>& s, const Targets<Real>& t, Real eps2, Law&& law) {
  for (std::size_t i = 0; i < t.n; ++i) {
    const Real tx = t.x[i], ty = t.y[i], tz = t.z[i];
    Accumulator<Real> acc;
    for (std::size_t j = 0; j < s.n; ++j) {
      const Real dx = s.x[j] - tx, dy = s.y[j] - ty, dz = s.z[j] - tz;
      law(j, dx, dy, dz, inverse_distance(dx * dx + dy * dy + dz * dz + eps2), acc);
    }
    t.ax[i] += acc.ax;
    t.ay[i] += acc.ay;
    t.az[i] += acc.az;
    t.phi[i] += acc.phi;
  }
}

template <class Real>
void cell_field_scalar(const SourceCells<Real>& s, const Targets<Real>& t, Real eps2, bool quadrupole) {
  // The law is chosen once per call, not per interaction.
  if (quadrupole) {
    cells_scalar(s, t, eps2, [&](std::size_t j, Real dx, Real dy, Real dz, Real inv, Accumulator<Real>& acc) {
      const Quadrupole<Real> Q{s.qxx[j], s.qxy[j], s.qxz[j], s.qyy[j], s.qyz[j], -(s.qxx[j] + s.qyy[j])};
      add_cell(dx, dy, dz, s.m[j], Q, inv, acc);
    });
  } else {
    cells_scalar(s, t, eps2, [&](std::size_t j, Real dx, Real dy, Real dz, Real inv, Accumulator<Real>& acc) {
      add_point(dx, dy, dz, s.m[j], inv, acc);
    });
  }
}

template <class Real>
void particle_field_simd(const SourceParticles<Real>& s, const Targets<Real>& t, Real eps2) {
  SWIRL_SIMD_DISPATCH(particle_field, s, t, eps2);
}

template <class Real>
void cell_field_simd(const SourceCells<Real>& s, const Targets<Real>& t, Real eps2, bool quadrupole) {
  SWIRL_SIMD_DISPATCH(cell_field, s, t, eps2, quadrupole);
}

}  // namespace

template <class Real>
void add_particle_field(const SourceParticles<Real>& s, const Targets<Real>& t, Real eps2, KernelPath path) {
  if (t.n == 0 || s.n == 0) return;
  if (path == KernelPath::Scalar)
    particle_field_scalar(s, t, eps2);
  else
    particle_field_simd(s, t, eps2);
}

template <class Real>
void add_cell_field(const SourceCells<Real>& s, const Targets<Real>& t, Real eps2, bool quadrupole, KernelPath path) {
  if (t.n == 0 || s.n == 0) return;
  if (path == KernelPath::Scalar)
    cell_field_scalar(s, t, eps2, quadrupole);
  else
    cell_field_simd(s, t, eps2, quadrupole);
}

template void add_particle_field<float>(const SourceParticles<float>&, const Targets<float>&, float, KernelPath);
template void add_particle_field<double>(const SourceParticles<double>&, const Targets<double>&, double, KernelPath);
template void add_cell_field<float>(const SourceCells<float>&, const Targets<float>&, float, bool, KernelPath);
template void add_cell_field<double>(const SourceCells<double>&, const Targets<double>&, double, bool, KernelPath);

}  // namespace swirl::gravity
