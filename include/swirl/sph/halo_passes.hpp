// The SPH grid passes (sph/grid_passes.hpp) on one rank's particles among its
// ghosts (dist/halo.hpp; docs/design/mpi.md, "SPH across ranks"): the
// library-level step of issue 19 item 3, before the Simulation runs on ranks.
//
// The caller, on every rank (collective):
//   frame = dist::global_key_frame(comm, p, request, fits)    request: SphFluid's order_request()
//   keys  = dist::keys_in_frame(frame, p)
//   dist::distribute_in_key_order(comm, p, keys, first, cuts)  (the one-rank order, migrated)
//   halo  = dist::Halo::find(comm, frame, keys, first, count, cuts, kHaloTail<Real>)
//   halo.insert(comm, p, keys, kHaloFields)                    exchange 1
//   grid.view(frame, keys, halo.global_index(), block_size)
//   halo_density_and_forces(comm, halo, grid, p, laws, ...)     exchange 2 inside
//   halo.remove(p, keys)
// halo_density_and_forces() computes density and pressure of the own
// particles (halo.owned()), sends them to the ranks that hold them as ghosts
// (halo.refresh), derives the ghosts' volumes m/ρ and p·m/ρ as the density
// pass does, then the gradient correction (when on) and the accelerations of
// the own particles. Each own particle's density, pressure and acceleration are
// the bits of the one-rank passes over all particles (same path, same
// instruction set): its neighbour ranges hold the one-rank particles in the
// one-rank order (dist/halo.hpp's invariants). Ghosts' accelerations are not
// computed. Units: SI, as sph_fluid.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "swirl/core/kernel_path.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/dist/halo.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/sph/grid_passes.hpp"
#include "swirl/sph/laws.hpp"

namespace swirl::sph {

// The global last particles every rank takes as ghosts: the widest batch of
// the explicit-SIMD passes (64 bytes, AVX-512) less one (dist/halo.hpp).
template <class Real>
inline constexpr std::size_t kHaloTail = 64 / sizeof(Real) - 1;

// What the passes read of a ghost before the density pass (exchange 1).
inline const std::vector<std::string> kHaloFields{"position", "velocity", "mass"};
// What they read of it after (exchange 2).
inline const std::vector<std::string> kHaloRefreshFields{"density", "pressure"};

// Returns the own particles' neighbour pairs (self excluded). between(): run
// after exchange 2, before the ghosts' volumes are derived (the boundary
// particles' mirrored pressure, sph_fluid.hpp, which reads the ghosts' fluid
// pressures and writes the own boundary particles' ρ, p, V and pV); when it
// returns true, density and pressure are exchanged again, so that the ghosts'
// entries are their owners' after it.
// candidates: as grid_density's (optional).
template <class Real, class Between>
std::uint64_t halo_density_and_forces(const dist::Communicator& comm, dist::Halo& halo,
                                      const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                                      const SphLaws<Real>& laws, std::size_t block_size, GridScratch<Real>& scratch,
                                      KernelPath path, Between&& between, std::span<std::uint64_t> candidates = {}) {
  const IndexRange own = halo.owned();
  const std::uint64_t pairs = grid_density(grid, p, laws, block_size, scratch, path, own, candidates);
  halo.refresh(comm, p, kHaloRefreshFields);
  if (between()) halo.refresh(comm, p, kHaloRefreshFields);
  // The ghosts' volumes, with the density pass's arithmetic (one division, one product).
  const Real *m = p.mass.data(), *rho = p.density.data(), *pr = p.pressure.data();
  auto volumes = [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      scratch.volume[i] = m[i] / rho[i];
      scratch.pressure_volume[i] = pr[i] * scratch.volume[i];
    }
  };
  volumes(0, own.begin);
  volumes(own.end, p.size());
  if (laws.corrected) grid_gradient_correction(grid, p, laws, block_size, scratch, own);
  grid_forces(grid, p, laws, block_size, scratch, path, own);
  return pairs;
}

template <class Real>
std::uint64_t halo_density_and_forces(const dist::Communicator& comm, dist::Halo& halo,
                                      const spatial::SortedCellGrid<Real>& grid, ParticleSet<Real>& p,
                                      const SphLaws<Real>& laws, std::size_t block_size, GridScratch<Real>& scratch,
                                      KernelPath path) {
  return halo_density_and_forces(comm, halo, grid, p, laws, block_size, scratch, path, [] { return false; });
}

}  // namespace swirl::sph
