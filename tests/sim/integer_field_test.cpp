// Integer particle fields through a whole run: a solver declares them, the
// shared particle order moves them with their particles every sort, and a
// checkpoint file carries them, so that a resumed run ends bit-identical to
// one that never stopped, for any thread count.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "swirl/core/random.hpp"
#include "swirl/force/uniform_gravity.hpp"
#include "swirl/io/checkpoint.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/lattice_mass.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;

// A solver whose force depends on two integer fields: "kind" (output, set by
// the test: -1, 0 or 1) pushes a particle up or down, and "visits" (internal,
// its own state) counts the evaluations that found the particle in the upper
// half of the box and nudges it sideways by that count modulo 3. A "kind" or
// a count that did not follow its particle through a sort, or that a
// checkpoint lost, changes the trajectories.
template <class Real>
class KindPush final : public Solver<Real> {
 public:
  std::string_view name() const override { return "kind_push"; }
  void declare_fields(ParticleSet<Real>& p) override {
    p.add_int_field("kind");
    p.add_int_field("visits", FieldUse::Internal);
  }
  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
    const std::int32_t* kind = p.int_field(p.find_int_field("kind")).data();
    std::int32_t* visits = p.int_field(p.find_int_field("visits")).data();
    parallel::for_blocks("kind_push", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) {
        if (p.position.z[i] > Real(0.5)) ++visits[i];
        p.acceleration.z[i] += Real(4) * Real(kind[i]);
        p.acceleration.x[i] += Real(0.5) * Real(visits[i] % 3 - 1);
      }
    });
  }
};

// n random particles in a closed unit box with an SPH fluid (sorted every
// sort by its cell grid, with a skin: the order's reference positions travel
// too), gravity and KindPush; kinds set by id.
template <class Real>
std::unique_ptr<Simulation<Real>> make_run(std::size_t n) {
  ParticleSet<Real> p(n);
  SplitMix64 rng(5);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      p.position[a][i] = Real(rng.uniform());
      p.velocity[a][i] = Real(4 * (rng.uniform() - 0.5));
    }
    p.mass[i] = Real(1000.0 / double(n));
    p.id[i] = i;
  }
  SimulationSettings settings;
  settings.dt = 1e-3;
  settings.block_size = 64;
  settings.box = boundary::BoxCollision<double>{{{0, 0, 0}, {1, 1, 1}}, 0.5};
  auto sim = std::make_unique<Simulation<Real>>(std::move(p), settings);
  sph::SphParameters params;
  params.smoothing_length = sph::smoothing_length_for_neighbours(25, 1.0 / double(n));
  params.sound_speed = 1;
  params.viscosity = 0.05;
  params.grid_skin = 0.2 * params.smoothing_length;
  sim->add_solver(std::make_unique<sph::SphFluid<Real>>(params));
  sim->add_solver(std::make_unique<UniformGravity<Real>>(Vec3<Real>{0, 0, Real(-9.81)}));
  sim->add_solver(std::make_unique<KindPush<Real>>());
  sim->prepare();
  auto& particles = sim->particles();
  auto& kind = particles.int_field(particles.find_int_field("kind"));
  for (std::size_t i = 0; i < n; ++i) kind[i] = static_cast<std::int32_t>(particles.id[i] % 3) - 1;
  return sim;
}

// Every real and integer field and the ids, bit for bit.
template <class Real>
void expect_bit_identical(const ParticleSet<Real>& a, const ParticleSet<Real>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  const auto fa = a.fields(), fb = b.fields();
  ASSERT_EQ(fa.size(), fb.size()) << what;
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      EXPECT_EQ(std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(Real)), 0) << what << ": " << fa[f].name;
  const auto ia = a.int_fields(), ib = b.int_fields();
  ASSERT_EQ(ia.size(), ib.size()) << what;
  for (std::size_t f = 0; f < ia.size(); ++f) {
    EXPECT_EQ(ia[f].name, ib[f].name) << what;
    EXPECT_EQ(std::memcmp(ia[f].data[0], ib[f].data[0], a.size() * sizeof(std::int32_t)), 0) << what << ": " << ia[f].name;
  }
  EXPECT_EQ(a.id, b.id) << what;
}

template <class Real>
class IntegerFieldTest : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(IntegerFieldTest, Precisions);

// The kinds follow their particles through every sort: after the run, each
// particle's kind is still the one its id was given, and the sorts did move
// particles (so the check means something).
TYPED_TEST(IntegerFieldTest, KindsFollowTheirParticlesThroughEverySort) {
  using Real = TypeParam;
  auto sim = make_run<Real>(600);
  sim->start();
  const auto epoch = sim->order().epoch();
  for (int s = 0; s < 25; ++s) sim->step();
  EXPECT_NE(sim->order().epoch(), epoch);
  const auto& p = sim->particles();
  const auto& kind = p.int_field(p.find_int_field("kind"));
  const auto& visits = p.int_field(p.find_int_field("visits"));
  bool moved = false, visited = false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(kind[i], static_cast<std::int32_t>(p.id[i] % 3) - 1) << "particle id " << p.id[i];
    moved = moved || p.id[i] != i;
    visited = visited || visits[i] > 0;
  }
  EXPECT_TRUE(moved);
  EXPECT_TRUE(visited);
}

TYPED_TEST(IntegerFieldTest, OneTwoAndThreeThreadsGiveTheSameBits) {
  using Real = TypeParam;
  const int before = parallel::thread_count();
  std::vector<ParticleSet<Real>> runs;
  for (int threads : {1, 2, 3}) {
    parallel::set_thread_count(threads);
    auto sim = make_run<Real>(800);
    sim->start();
    for (int s = 0; s < 20; ++s) sim->step();
    runs.push_back(sim->particles());
  }
  parallel::set_thread_count(before);
  expect_bit_identical(runs[0], runs[1], "2 threads");
  expect_bit_identical(runs[0], runs[2], "3 threads");
}

// Stopped after 12 steps into a checkpoint file and resumed from it in a
// fresh simulation (on another thread count), the run ends as the one that
// never stopped: "kind" and "visits" came back from the file, in the file's
// particle order.
TYPED_TEST(IntegerFieldTest, ResumingFromACheckpointFileIsBitIdentical) {
  using Real = TypeParam;
  const int before = parallel::thread_count();
  parallel::set_thread_count(1);
  auto straight = make_run<Real>(600);
  straight->start();
  for (int s = 0; s < 30; ++s) straight->step();

  io::test::TempDir dir;
  auto first = make_run<Real>(600);
  first->start();
  for (int s = 0; s < 12; ++s) first->step();
  NamedValues state;
  first->save_state(state);
  io::write_checkpoint(dir / "c.swc", first->particles(),
                       {sizeof(Real), first->particles().size(), 1, first->step_count(), first->time()}, state);

  parallel::set_thread_count(2);
  auto second = make_run<Real>(600);  // declares the fields, kinds set in the initial order
  io::CheckpointValues values;
  const auto header = io::read_checkpoint(dir / "c.swc", second->particles(), values);
  EXPECT_EQ(header.version, io::kCheckpointVersion);
  expect_bit_identical(second->particles(), first->particles(), "read back");
  second->resume(first->clock(), values);
  for (int s = 0; s < 18; ++s) second->step();
  parallel::set_thread_count(before);
  expect_bit_identical(straight->particles(), second->particles(), "resumed");
  EXPECT_EQ(straight->time(), second->time());
}

}  // namespace
