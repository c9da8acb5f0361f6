// Results are bit-identical for any thread count.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>

#include "swirl/force/uniform_gravity.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"
#include "test_support.hpp"

namespace {

using swirl::ParticleSet;

template <class Real>
class ThreadsTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ThreadsTest, Precisions);

template <class Real>
ParticleSet<Real> run_with(int threads) {
  swirl::parallel::set_thread_count(threads);
  constexpr std::size_t n = 3000;
  ParticleSet<Real> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      p.position[axis][i] = Real(0.02 + 0.96 * swirl::testing::hash01(3 * i + axis));
      p.velocity[axis][i] = Real(4.0 * (swirl::testing::hash01(77777 + 3 * i + axis) - 0.5));
    }
    p.mass[i] = Real(1);
    p.id[i] = i;
  }
  swirl::SimulationSettings settings;
  settings.dt = 0.004;
  settings.block_size = 64;  // 47 blocks: at least 8 per thread for 1, 2 and 3 threads
  settings.box = swirl::boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.7};
  swirl::Simulation<Real> sim(std::move(p), settings);
  sim.add_solver(std::make_unique<swirl::UniformGravity<Real>>(swirl::Vec3<Real>{Real(0.5), 0, Real(-9.81)}));
  sim.add_solver(std::make_unique<swirl::testing::Spring<Real>>(Real(3), Real(0.5)));
  sim.start();
  for (int s = 0; s < 100; ++s) sim.step();
  return sim.particles();
}

template <class Real>
bool bit_identical(const ParticleSet<Real>& a, const ParticleSet<Real>& b) {
  const auto fa = a.fields(), fb = b.fields();
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      if (std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(Real)) != 0) return false;
  return a.id == b.id;
}

TYPED_TEST(ThreadsTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  const auto one = run_with<TypeParam>(1);
  EXPECT_TRUE(bit_identical(one, run_with<TypeParam>(2)));
  EXPECT_TRUE(bit_identical(one, run_with<TypeParam>(3)));
}

}  // namespace
