// halo_figures: the SPH halo's size and traffic at any size, under mpirun
// (dist/halo.hpp; the figures of docs/design/mpi.md, "SPH across ranks").
//
//   mpirun -n RANKS build/halo_figures N [SKIN]
//
// A jittered lattice of N³ water particles (spacing 1 cm, ±17 % jitter,
// h = 2.1 spacings; SKIN in spacings, default 0), starting on the ranks in
// lattice order, sorted into the global row-major cell order with cuts that
// balance the particle count; then the ghosts found, inserted (exchange 1:
// position, velocity, mass, in double) and refreshed (exchange 2: density,
// pressure). Rank 0 prints the ghosts per particle of the whole set and per
// own particle of the largest rank, and each exchange's bytes and messages per
// rank (mean and largest). Counts only: no timing is printed.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/dist/halo.hpp"
#include "swirl/dist/key_cuts.hpp"
#include "swirl/dist/key_order.hpp"
#include "swirl/spatial/cell_grid.hpp"

namespace {

using namespace swirl;

double unit_hash(std::uint64_t g, std::uint64_t salt) {
  std::uint64_t x = (g + 1) * 0x9E3779B97F4A7C15ull + salt * 0xBF58476D1CE4E5B9ull;
  x ^= x >> 31;
  x *= 0x94D049BB133111EBull;
  x ^= x >> 29;
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}

struct Summary {
  double mean = 0;
  std::uint64_t max = 0;
};

Summary over_ranks(const dist::Communicator& comm, std::uint64_t value) {
  const std::vector<std::uint64_t> all = comm.all_gather(value);
  Summary s;
  for (std::uint64_t v : all) {
    s.mean += double(v) / double(all.size());
    s.max = std::max(s.max, v);
  }
  return s;
}

int run(int argc, char** argv) {
  const dist::Communicator& comm = dist::Communicator::world();
  if (argc < 2) {
    if (comm.is_root()) std::fprintf(stderr, "usage: halo_figures N [SKIN_SPACINGS]\n");
    return 2;
  }
  const std::uint64_t n = std::strtoull(argv[1], nullptr, 10);
  const double skin_spacings = argc > 2 ? std::strtod(argv[2], nullptr) : 0.0;
  const double spacing = 0.01, h = 2.1 * spacing, skin = skin_spacings * spacing;
  const std::uint64_t count = n * n * n;
  const auto ranks = static_cast<std::uint64_t>(comm.size()), r = static_cast<std::uint64_t>(comm.rank());
  const std::uint64_t first = count * r / ranks, end = count * (r + 1) / ranks;

  ParticleSet<double> p(end - first);
  for (std::uint64_t g = first; g < end; ++g) {
    const std::size_t i = g - first;
    const std::uint64_t c[3] = {g % n, g / n % n, g / n / n};
    for (int a = 0; a < 3; ++a) {
      p.position[a][i] = spacing * (double(c[a]) + 0.35 * (unit_hash(g, std::uint64_t(a)) - 0.5));
      p.velocity[a][i] = 0.05 * (unit_hash(g, 3 + std::uint64_t(a)) - 0.5);
    }
    p.mass[i] = 1000 * spacing * spacing * spacing;
    p.id[i] = g;
  }
  const spatial::OrderRequest request{true, spatial::SortedCellGrid<double>::cell_length_for(h, skin), 0.5 * skin,
                                      spatial::CellOrder::Rows};
  bool fits = false;
  const spatial::KeyFrame frame = dist::global_key_frame(comm, p, request, fits);
  if (!fits) throw std::runtime_error("the cells do not fit");
  std::vector<std::uint64_t> keys = dist::keys_in_frame(frame, p);
  const std::vector<std::uint64_t> cuts =
      dist::balanced_cut_keys(comm, keys, std::vector<std::uint64_t>(keys.size(), 1));
  const dist::Distribution d = dist::distribute_in_key_order(comm, p, keys, first, cuts);
  dist::Halo halo = dist::Halo::find(comm, frame, keys, d.first_global_index, d.global_count, cuts,
                                          7);  // sph::kHaloTail<double>
  halo.insert(comm, p, keys, {"position", "velocity", "mass"});
  halo.refresh(comm, p, {"density", "pressure"});

  const std::uint64_t own = halo.owned_count(), ghosts = halo.ghost_count();
  const std::uint64_t total_ghosts = comm.sum(ghosts);
  const Summary own_s = over_ranks(comm, own), ghost_s = over_ranks(comm, ghosts);
  // The largest ratio of ghosts to own particles on one rank, in parts per million.
  const Summary ratio = over_ranks(comm, own > 0 ? ghosts * 1000000 / own : 0);
  const Summary ask = over_ranks(comm, halo.request_traffic().bytes_sent),
                ins = over_ranks(comm, halo.insert_traffic().bytes_sent),
                ref = over_ranks(comm, halo.refresh_traffic().bytes_sent),
                msg = over_ranks(comm, halo.insert_traffic().messages);
  if (comm.is_root()) {
    std::printf("particles %llu (%llu^3), ranks %d, cells %.4g m (h + %.2g spacings)\n", (unsigned long long)count,
                (unsigned long long)n, comm.size(), frame.cell_length(), skin_spacings);
    std::printf("ghosts: %.4f per particle of the set; per own particle: mean %.4f, largest rank %.4f\n",
                double(total_ghosts) / double(count), ghost_s.mean / own_s.mean, double(ratio.max) / 1e6);
    std::printf("per rank (mean / largest): requests %.0f / %llu B, exchange 1 %.0f / %llu B in %.2f / %llu messages, "
                "exchange 2 %.0f / %llu B\n",
                ask.mean, (unsigned long long)ask.max, ins.mean, (unsigned long long)ins.max, msg.mean,
                (unsigned long long)msg.max, ref.mean, (unsigned long long)ref.max);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  swirl::dist::MpiSession mpi(argc, argv);
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "halo_figures on rank %d: %s\n", swirl::dist::Communicator::world().rank(), e.what());
    swirl::dist::Communicator::world().abort(1);
  }
}
