// The SPH grid passes across ranks (sph/halo_passes.hpp over dist/halo.hpp),
// run by CTest on 1-4 ranks: every own particle's density, pressure and
// acceleration are byte-identical to a one-rank computation of the whole set,
// which each rank computes itself. For float and double, row-major and Morton
// cells (and rows of h + skin), the scalar passes and the explicit-SIMD copy of
// every instruction set this CPU runs, with and without the gradient
// correction; then again after a step that moves particles across the cuts
// (migration, new ghosts), the ranks then on two threads each.
#include "swirl/sph/halo_passes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "dist/lattice_block.hpp"
#include "swirl/core/simd_dispatch.hpp"
#include "swirl/dist/key_cuts.hpp"
#include "swirl/dist/key_order.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/spatial/cell_grid.hpp"
#include "swirl/spatial/particle_order.hpp"
#include "swirl/sph/grid_passes.hpp"
#include "swirl/sph/parameters.hpp"

namespace swirl::dist {
namespace {

constexpr std::size_t kBlock = 64;

// A way to run the passes: scalar, or the SIMD copy of one instruction set.
struct Path {
  KernelPath path;
  simd::Isa isa;
  std::string name() const {
    return path == KernelPath::Scalar ? "scalar" : "simd/" + std::string(simd::isa_name(isa));
  }
};

std::vector<Path> paths() {
  std::vector<Path> out{{KernelPath::Scalar, simd::active()}};
  for (simd::Isa isa : simd::kCompiledIsas)
    if (simd::usable(isa)) out.push_back({KernelPath::Simd, isa});
  return out;
}

sph::SphParameters parameters(bool corrected) {
  sph::SphParameters s;
  s.smoothing_length = test::kH;
  s.rest_density = test::kRestDensity;
  s.sound_speed = 5;
  s.viscosity = 0.02;
  s.gradient_correction = corrected;
  return s;
}

// Density, pressure and acceleration of particles, in one order.
template <class Real>
struct Values {
  std::vector<Real> density, pressure, ax, ay, az;
  std::vector<std::uint64_t> id;
  void append(const ParticleSet<Real>& p, std::size_t i) {
    density.push_back(p.density[i]);
    pressure.push_back(p.pressure[i]);
    ax.push_back(p.acceleration.x[i]);
    ay.push_back(p.acceleration.y[i]);
    az.push_back(p.acceleration.z[i]);
    id.push_back(p.id[i]);
  }
};

template <class Real>
void zero_accelerations(ParticleSet<Real>& p) {
  for (int a = 0; a < 3; ++a) std::fill(p.acceleration[a].begin(), p.acceleration[a].end(), Real(0));
}

// The one-rank passes over the whole set (the reference; p stays in the order's sort).
template <class Real>
Values<Real> one_rank(ParticleSet<Real>& p, spatial::ParticleOrder<Real>& order, const sph::SphLaws<Real>& laws,
                      const Path& path, std::uint64_t& pairs) {
  order.update(p, kBlock);
  spatial::SortedCellGrid<Real> grid;
  if (!grid.view(order, kBlock)) throw std::runtime_error("test set-up: no grid");
  simd::ScopedIsa isa(path.isa);
  sph::GridScratch<Real> scratch;
  zero_accelerations(p);
  pairs = sph::grid_density(grid, p, laws, kBlock, scratch, path.path);
  if (laws.corrected) sph::grid_gradient_correction(grid, p, laws, kBlock, scratch);
  sph::grid_forces(grid, p, laws, kBlock, scratch, path.path);
  Values<Real> v;
  for (std::size_t i = 0; i < p.size(); ++i) v.append(p, i);
  return v;
}

// The same passes on this rank's particles with their ghosts; p holds the own
// particles (in the previous global order from `first`) and keeps them.
template <class Real>
Values<Real> with_ghosts(const Communicator& comm, ParticleSet<Real>& p, std::uint64_t& first,
                         std::vector<std::uint64_t>& cuts, const spatial::OrderRequest& request,
                         const sph::SphLaws<Real>& laws, const Path& path, std::uint64_t& pairs) {
  bool fits = false;
  const spatial::KeyFrame frame = global_key_frame(comm, p, request, fits);
  if (!fits) throw std::runtime_error("test set-up: the cells do not fit");
  std::vector<std::uint64_t> keys = keys_in_frame(frame, p);
  if (cuts.empty() && comm.size() > 1) cuts = balanced_cut_keys(comm, keys, std::vector<std::uint64_t>(keys.size(), 1));
  const Distribution d = distribute_in_key_order(comm, p, keys, first, cuts);
  first = d.first_global_index;
  Halo halo = Halo::find(comm, frame, keys, d.first_global_index, d.global_count, cuts, sph::kHaloTail<Real>);
  halo.insert(comm, p, keys, sph::kHaloFields);
  spatial::SortedCellGrid<Real> grid;
  grid.view(frame, keys, halo.global_index(), kBlock);
  simd::ScopedIsa isa(path.isa);
  sph::GridScratch<Real> scratch;
  zero_accelerations(p);
  pairs = sph::halo_density_and_forces(comm, halo, grid, p, laws, kBlock, scratch, path.path);
  Values<Real> v;
  for (std::size_t i = halo.owned().begin; i < halo.owned().end; ++i) v.append(p, i);
  halo.remove(p, keys);
  return v;
}

// Counts the own particles whose values differ in any bit from the reference's at their global index.
template <class Real>
std::uint64_t differing(const Values<Real>& got, const Values<Real>& want, std::uint64_t first) {
  std::uint64_t bad = 0;
  for (std::size_t i = 0; i < got.id.size(); ++i) {
    const std::size_t g = first + i;
    const bool same = got.id[i] == want.id[g] &&
                      std::memcmp(&got.density[i], &want.density[g], sizeof(Real)) == 0 &&
                      std::memcmp(&got.pressure[i], &want.pressure[g], sizeof(Real)) == 0 &&
                      std::memcmp(&got.ax[i], &want.ax[g], sizeof(Real)) == 0 &&
                      std::memcmp(&got.ay[i], &want.ay[g], sizeof(Real)) == 0 &&
                      std::memcmp(&got.az[i], &want.az[g], sizeof(Real)) == 0;
    if (!same) ++bad;
  }
  return bad;
}

struct ThreadCount {
  explicit ThreadCount(int n) : saved(parallel::thread_count()) { parallel::set_thread_count(n); }
  ~ThreadCount() { parallel::set_thread_count(saved); }
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;
  int saved;
};

template <class Real>
class SphHaloTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SphHaloTest, Precisions);

TYPED_TEST(SphHaloTest, OwnParticlesAreTheOneRankBitsBeforeAndAfterMigration) {
  using Real = TypeParam;
  const Communicator& comm = Communicator::world();
  const test::Slice slice = test::initial_slice(comm);
  struct Cells {
    spatial::CellOrder curve;
    double skin;  // m: cells of h + skin
    bool corrected;
  };
  const double skin = 0.3 * test::kSpacing;
  for (const Cells cells : {Cells{spatial::CellOrder::Rows, 0, false}, Cells{spatial::CellOrder::Rows, 0, true},
                            Cells{spatial::CellOrder::Morton, 0, false}, Cells{spatial::CellOrder::Morton, 0, true},
                            Cells{spatial::CellOrder::Rows, skin, false}}) {
    {
      const sph::SphParameters params = parameters(cells.corrected);
      const sph::SphLaws<Real> laws(params);
      const spatial::OrderRequest request{
          true, spatial::SortedCellGrid<Real>::cell_length_for(test::kH, cells.skin), 0, cells.curve};
      for (const Path& path : paths()) {
        SCOPED_TRACE(std::string(cells.curve == spatial::CellOrder::Rows ? "rows" : "morton") +
                     (cells.skin > 0 ? " of h + skin" : "") + (cells.corrected ? ", corrected, " : ", ") +
                     path.name());
        ParticleSet<Real> all, mine;
        test::fill_block(all, 0, test::kParticles);
        test::fill_block(mine, slice.first, slice.end);
        spatial::ParticleOrder<Real> order;
        order.set_request(request);
        std::uint64_t first = slice.first;
        std::vector<std::uint64_t> cuts;
        for (int step = 0; step < 2; ++step) {
          std::uint64_t want_pairs = 0, got_pairs = 0;
          const Values<Real> want = one_rank(all, order, laws, path, want_pairs);
          // The second step on two threads per rank: the own range's blocks, not the bits, change.
          const ThreadCount threads(step == 0 ? 1 : 2);
          const Values<Real> got = with_ghosts(comm, mine, first, cuts, request, laws, path, got_pairs);
          const std::uint64_t bad = comm.sum(differing(got, want, first));
          EXPECT_EQ(bad, 0u) << "step " << step << ": own particles whose density, pressure or acceleration "
                             << "differ from the one-rank bits, over all ranks";
          EXPECT_EQ(comm.sum(std::uint64_t(got.id.size())), test::kParticles);
          EXPECT_EQ(comm.sum(got_pairs), want_pairs);
          // The step: the same drift on both, the reference in its sorted order.
          test::drift(all, 0, all.size());
          test::drift(mine, 0, mine.size());
        }
      }
    }
  }
}

}  // namespace
}  // namespace swirl::dist
