// The grid's cell orders and Verlet skin inside the SPH fluid: every step the
// pairs found equal brute force on the positions of that evaluation, the skin
// skips sorts, and the results stay bit-identical for 1, 2 and 3 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "sph_test_support.hpp"
#include "swirl/spatial/brute_force.hpp"

namespace {

using namespace swirl;

struct Setup {
  std::size_t n = 2000;
  spatial::CellOrder order = spatial::CellOrder::Rows;
  double skin_over_h = 0;
};

// n random particles in a closed unit box (~25 neighbours), moving fast
// enough (up to 3 m/s per axis, with gravity) that a skin of 0.2 h is used up
// every few steps.
template <class Real>
std::unique_ptr<Simulation<Real>> make_box(const Setup& s, double* h_out = nullptr) {
  const double rho0 = 1000;
  const double h = sph::smoothing_length_for_neighbours(25, 1.0 / double(s.n));
  ParticleSet<Real> p(s.n);
  SplitMix64 rng(91);
  for (std::size_t i = 0; i < s.n; ++i) {
    for (int a = 0; a < 3; ++a) {
      p.position[a][i] = Real(rng.uniform());
      p.velocity[a][i] = Real(6 * (rng.uniform() - 0.5));
    }
    p.mass[i] = Real(rho0 / double(s.n));
    p.id[i] = i;
  }
  SimulationSettings settings;
  settings.dt = 1e-3;
  settings.block_size = 64;
  settings.box = boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.5};
  auto sim = std::make_unique<Simulation<Real>>(std::move(p), settings);
  sph::SphParameters params;
  params.smoothing_length = h;
  params.sound_speed = 1;
  params.viscosity = 0.05;
  params.cell_order = s.order;
  params.grid_skin = s.skin_over_h * h;
  sim->add_solver(std::make_unique<sph::SphFluid<Real>>(params));
  sim->add_solver(std::make_unique<UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-9.81)}));
  sim->start();
  if (h_out) *h_out = h;
  return sim;
}

template <class Real>
const sph::SphFluid<Real>& fluid_of(const Simulation<Real>& sim) {
  return dynamic_cast<const sph::SphFluid<Real>&>(*sim.solvers().front());
}

template <class Real>
class GridSkinTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(GridSkinTest, Precisions);

// The pair count of every evaluation equals brute force's, and each
// particle's density equals the brute-force sum within rounding.
TYPED_TEST(GridSkinTest, EveryStepFindsTheBruteForcePairs) {
  using Real = TypeParam;
  for (auto order : {spatial::CellOrder::Rows, spatial::CellOrder::Morton})
    for (double skin : {0.0, 0.2}) {
      double h = 0;
      auto sim = make_box<Real>({1000, order, skin}, &h);
      const int steps = 20;
      for (int k = 0; k < steps; ++k) {
        // The state the next evaluation sees: the positions after the drift
        // are those of the force evaluation at the end of the step.
        sim->step();
        const auto& p = sim->particles();
        const auto pairs = spatial::brute_force_pairs(p, Real(h));
        const double found = fluid_of(*sim).mean_neighbours() * double(p.size());
        ASSERT_EQ(std::llround(found), static_cast<long long>(pairs.size()))
            << "step " << k << ", skin " << skin << ", morton " << (order == spatial::CellOrder::Morton);
      }
      const auto sorts = sim->order().sorts();
      if (skin > 0) {
        EXPECT_LT(sorts, std::uint64_t(steps));  // the skin skipped sorts ...
        EXPECT_GT(sorts, std::uint64_t(2));      // ... and was used up by the motion
      } else {
        EXPECT_GE(sorts, std::uint64_t(steps));  // one per evaluation
      }
    }
}

// With a skin the memory order stays put between sorts; the results are
// still bit-identical for 1, 2 and 3 threads.
TYPED_TEST(GridSkinTest, BitIdenticalForOneTwoAndThreeThreads) {
  using Real = TypeParam;
  const int before = parallel::thread_count();
  for (auto order : {spatial::CellOrder::Rows, spatial::CellOrder::Morton}) {
    std::vector<ParticleSet<Real>> runs;
    for (int threads : {1, 2, 3}) {
      parallel::set_thread_count(threads);
      auto sim = make_box<Real>({800, order, 0.2});
      for (int k = 0; k < 12; ++k) sim->step();
      runs.push_back(sim->particles());
    }
    for (std::size_t r = 1; r < runs.size(); ++r) {
      const auto fa = runs[0].fields(), fb = runs[r].fields();
      ASSERT_EQ(fa.size(), fb.size());
      for (std::size_t f = 0; f < fa.size(); ++f)
        for (int c = 0; c < fa[f].components; ++c)
          EXPECT_EQ(0, std::memcmp(fa[f].data[c], fb[f].data[c], runs[0].size() * sizeof(Real)))
              << fa[f].name << " run " << r;
      EXPECT_EQ(runs[0].id, runs[r].id);
    }
  }
  parallel::set_thread_count(before);
}

// One step with a skin, in Morton order, against one step of the default
// (rows, no skin) per particle: the same pairs, summed in another order.
TYPED_TEST(GridSkinTest, OneStepAgreesWithTheDefaultPerParticle) {
  using Real = TypeParam;
  auto a = make_box<Real>({1500});
  auto b = make_box<Real>({1500, spatial::CellOrder::Morton, 0.3});
  a->step();
  b->step();
  const auto &pa = a->particles(), &pb = b->particles();
  std::vector<std::size_t> at(pb.size());
  for (std::size_t i = 0; i < pb.size(); ++i) at[pb.id[i]] = i;
  const double tolerance = std::is_same_v<Real, float> ? 1e-5 : 1e-12;
  for (std::size_t i = 0; i < pa.size(); ++i) {
    const std::size_t j = at[pa.id[i]];
    EXPECT_NEAR(pb.density[j], pa.density[i], tolerance * pa.density[i]) << "id " << pa.id[i];
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(pb.position[c][j], pa.position[c][i], tolerance) << "id " << pa.id[i];
  }
}

}  // namespace
