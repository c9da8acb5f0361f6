#include "swirl/sim/footprint.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <unistd.h>

#include <fmt/format.h>

#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/validate.hpp"

namespace swirl::sim {

namespace {

constexpr char kCounted[] =
    "counted: the particle fields, the neighbour lists the smoothing length gives (and DFSPH's kept pairs), "
    "sph.hash.buckets, a dense sph.grid.table";

}  // namespace

Footprint footprint(const scene::Scene& scene, int ranks) {
  ranks = std::max(ranks, 1);
  const double n = static_cast<double>(scene::count_particles(scene));
  const double real = scene.precision == scene::Precision::Float ? 4 : 8;
  // 16 reals and an id of fields.
  const double fields = 16 * real + 8;
  // The scene's double copy of the particles while they are built (on rank 0 alone).
  const double building = 56;
  // Per particle a solver keeps: tree nodes for gravity; sorted copies and
  // (index, r²) per neighbour twice (block lists and the CSR) for SPH.
  double solver = 0;
  double fixed = 0;
  double support_in_spacings = 0;  // SPH: h over the particle spacing
  if (scene.nbody) solver += 2 * 96;
  if (scene.sph) {
    const sph::SphParameters& sph = *scene.sph;
    const double h = sph.smoothing_length;
    // Neighbours: ~40 at the usual k, more when h is large against the
    // spacing (from the box's mean density: fluid fills part of it, so at least 40).
    double neighbours = 40;
    if (scene.walls) {
      const Vec3d size = scene.box.hi - scene.box.lo;
      const double volume = size.x * size.y * size.z;
      if (volume > 0) neighbours = std::max(neighbours, std::min(n, 4.18879 * h * h * h * n / volume));
    }
    support_in_spacings = std::cbrt(neighbours / 4.18879);  // neighbours = 4π/3 (h/s)³
    solver += 40 + 2 * neighbours * (4 + real);
    // DFSPH keeps each evaluation's pairs, {j, g(r_ij)}, for its solves (sph/dfsph_pairs.hpp),
    // and in float its SIMD passes pack each particle's {z, x, y, m} and {v_z, v_x, v_y, 0}.
    if (sph.method == sph::SphMethod::Dfsph) solver += neighbours * (4 + real) + (real == 4 ? 32 : 0);
    if (sph.neighbour_search == sph::NeighbourSearch::Hash) {
      // The counting sort's offsets and one count per bucket for each chunk (thread).
      const double buckets = sph.buckets ? double(sph.buckets) : 1.6 * n + 1;
      const double chunks = std::min(double(parallel::thread_count()), std::floor(n / 4096) + 1);
      fixed += 4 * buckets * (1 + chunks);
    } else {
      fixed += 4 * scene::dense_cell_table_keys(scene);  // one start per cell key
    }
  }
  Footprint f;
  f.frame = n * (fields + 16) + 4096;
  if (ranks == 1) {
    f.memory = {n * (fields + building + solver) + fixed};
    return f;
  }
  // A rank's share, and what it holds of the others: SPH ghosts, a layer of
  // the kernel support around its range taken as a cube of its particles
  // (key ranges are less compact than cubes, so the layer is doubled), each
  // also in an exchange buffer; gravity's imported tree, taken as large as
  // its own.
  const double mine = std::ceil(n / ranks);
  double ghosts = 0;
  if (scene.sph) {
    const double side = std::cbrt(mine) + 4 * support_in_spacings;
    ghosts = std::min(n - mine, side * side * side - mine);
  }
  // The direct sum and the FMM are replicated: every rank gathers the whole
  // set (fields, keys, the field) and the FMM builds its tree over it.
  double imported = scene.nbody ? mine * 2 * 96 : 0;
  if (scene.nbody && (scene.nbody->method == gravity::Method::Direct || scene.nbody->method == gravity::Method::Fmm))
    imported = n * (fields + 8 + 4 * real + (scene.nbody->method == gravity::Method::Fmm ? 2 * 96 : 0));
  const double rank = (mine + ghosts) * (fields + solver) + ghosts * fields + imported + fixed;
  f.memory.assign(static_cast<std::size_t>(ranks), rank);
  // Rank 0 builds the whole set (and the scene's double copy), and gathers
  // it for every VTK or CSV frame, which its writer encodes (checkpoints and
  // HDF5 frames gather nothing whole; the building peak alone is of that order): 288 B a
  // particle in float, where the dam break at 3.84·10⁶ particles on 8 ranks
  // measured 340 B (docs/design/mpi.md).
  f.memory[0] += n * (2 * fields + building + (fields + 16));
  return f;
}

std::string memory_refusal(const scene::Scene& scene, const std::vector<RankHost>& hosts) {
  const int ranks = static_cast<int>(std::max<std::size_t>(hosts.size(), 1));
  const Footprint f = footprint(scene, ranks);
  const std::size_t n = scene::count_particles(scene);
  if (ranks == 1) {
    const double available = hosts.empty() ? double(memory_available()) : double(hosts[0].free_bytes);
    if (available > 0 && f.memory[0] > 0.9 * available)
      return fmt::format("{}: {} particles need about {:.1f} GB of memory, more than the {:.1f} GB this machine has "
                         "free ({})",
                         scene.file, n, f.memory[0] / 1e9, available / 1e9, kCounted);
    return {};
  }
  struct Host {
    double need = 0;
    double free = 0;  // the least any of its ranks saw
    int ranks = 0;
  };
  std::map<std::string, Host> by_host;
  for (std::size_t r = 0; r < hosts.size(); ++r) {
    Host& h = by_host[hosts[r].host];
    h.need += f.memory[r];
    const double free = double(hosts[r].free_bytes);
    h.free = h.ranks == 0 ? free : std::min(h.free, free);
    ++h.ranks;
  }
  for (const auto& [name, h] : by_host) {
    if (h.free <= 0 || h.need <= 0.9 * h.free) continue;
    return fmt::format("{}: {} particles on {} MPI ranks need about {:.1f} GB of memory on each rank and {:.1f} GB on "
                       "rank 0 (which builds the particles and gathers each frame): {:.1f} GB on host {} for its {} "
                       "rank{}, more than the {:.1f} GB free there ({}, the ghosts and imported tree of each rank); "
                       "run on more hosts or with fewer particles",
                       scene.file, n, ranks, f.memory[ranks - 1] / 1e9, f.memory[0] / 1e9, h.need / 1e9, name, h.ranks,
                       h.ranks > 1 ? "s" : "", h.free / 1e9, kCounted);
  }
  return {};
}

std::uint64_t memory_available() {
  const long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
  return pages > 0 && size > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(size) : 0;
}

}  // namespace swirl::sim
