// A mesh obstacle (kind = "obstacle_mesh", scene/mesh_sampling.hpp) in a
// running fluid: a dam break against a stepped block with sharp edges, read
// from a binary STL, checked after every step for a fluid particle inside the
// block (DFSPH: none; the thesis's solver: at most 1 %, see below); and the
// run bit-identical on one and two threads and across a resume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "io/io_test_util.hpp"
#include "scene/mesh_test_util.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"

namespace {

using namespace swirl;
namespace fs = std::filesystem;

// The block of tests/scene/mesh_test_util.hpp at half a millimetre per unit:
// 0.12 m long, 0.1 m wide (the whole tank), its high step (0.08 m) at x in
// [x0, x0 + 0.06], its low step (0.04 m) at [x0 + 0.06, x0 + 0.12], facing the
// water that comes from +x.
constexpr double kX0 = 0.1;
bool inside_block(const Vec3d& p) {
  if (!(p.x > kX0 && p.x < kX0 + 0.12 && p.y > 0 && p.y < 0.1 && p.z > 0)) return false;
  return p.z < (p.x < kX0 + 0.06 ? 0.08 : 0.04);
}
// How far p (outside) is from the block's surface, in x–z (the block spans the tank's width).
double to_block(const Vec3d& p) {
  const auto box = [&](double lo_x, double hi_x, double hi_z) {
    const double dx = std::max({lo_x - p.x, 0.0, p.x - hi_x}), dz = std::max(p.z - hi_z, 0.0);
    return std::hypot(dx, dz);
  };
  return std::min(box(kX0, kX0 + 0.06, 0.08), box(kX0, kX0 + 0.12, 0.04));
}

// The dam break: a tank 0.5 × 0.1 × 0.4 m with walls of particles, water
// 0.15 × 0.1 × 0.25 m against the far wall (x in [0.35, 0.5]) at spacing
// 0.02, the block from `mesh` on the floor.
std::string dam_break(const fs::path& mesh, std::string_view method, double dt) {
  return fmt::format(R"(
[simulation]
precision = "double"
dt = "adaptive"
dt_max = {dt}
end_time = 0.45
block_size = 64
[box]
min = [0.0, 0.0, 0.0]
max = [0.5, 0.1, 0.4]
walls = "particles"
[forces]
gravity = [0.0, 0.0, -9.81]
[sph]
neighbours = 30
rest_density = 1000.0
sound_speed = 20.0
viscosity = 0.1
negative_pressure = "zero"
method = "{method}"
[[particles]]
kind = "fluid_block"
min = [0.35, 0.0, 0.0]
max = [0.5, 0.1, 0.25]
spacing = 0.02
[[particles]]
kind = "obstacle_mesh"
file = "{mesh}"
scale = 0.0005
translate = [{x0}, 0.0, 0.0]
)",
                     fmt::arg("dt", dt), fmt::arg("method", method), fmt::arg("mesh", mesh.string()),
                     fmt::arg("x0", kX0));
}

const std::int32_t* kinds(const ParticleSet<double>& p) { return p.int_field(p.find_int_field(kKindField)).data(); }

class MeshBoundary : public ::testing::Test {
 protected:
  void SetUp() override { io::test::spit(dir_ / "block.stl", scene::test::binary_stl(scene::test::step_block())); }
  Simulation<double> build(std::string_view method, double dt) {
    return sim::build_simulation<double>(scene::parse_scene(dam_break(dir_ / "block.stl", method, dt), "dam.toml"));
  }
  io::test::TempDir dir_;
};

// DFSPH: no fluid particle ever inside the block, checked after every step.
// The thesis's solver: a one-layer shell is not always enough (docs/sph.md,
// "Mesh obstacles"): at dt_max = 4e-4 none entered, but of twelve dt_max from
// 2.8e-4 to 1e-3 one (5.2e-4) let one particle through the low step's top,
// where it then stayed. What holds there, and is tested: the fluid stays out
// but for at most 1 % of its particles at any step.
TEST_F(MeshBoundary, NoFluidParticleEntersASteppedBlockWithSharpEdges) {
  for (const char* method : {"dfsph", "wcsph"}) {
    const bool dfsph = std::string(method) == "dfsph";
    Simulation<double> sim = build(method, dfsph ? 0.004 : 4e-4);
    sim.start();
    std::size_t boundary = 0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i) boundary += is_boundary(kinds(sim.particles())[i]) ? 1 : 0;
    const std::size_t fluid = sim.particles().size() - boundary;
    double closest = 1, furthest_left = 1;
    std::size_t most_inside = 0;
    int steps = 0;
    while (sim.time() < 0.45) {
      sim.step();
      ++steps;
      const ParticleSet<double>& p = sim.particles();
      const std::int32_t* kind = kinds(p);
      std::size_t inside = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (is_boundary(kind[i])) continue;
        const Vec3d x = p.position.get(i);
        if (inside_block(x)) {
          ++inside;
          if (!dfsph) continue;
        }
        ASSERT_FALSE(inside_block(x)) << method << ": particle id " << p.id[i] << " inside the block at step " << steps
                                      << ", t = " << sim.time() << " s, at (" << x.x << ", " << x.y << ", " << x.z
                                      << ")";
        closest = std::min(closest, to_block(x));
        furthest_left = std::min(furthest_left, x.x);
      }
      most_inside = std::max(most_inside, inside);
      ASSERT_LE(inside * 100, fluid) << method << ": " << inside << " of " << fluid << " particles inside at step "
                                     << steps;
    }
    std::printf("%s: %d steps, %zu fluid and %zu boundary particles; the fluid came within %.4f m of the block and "
                "to x = %.3f m; at most %zu inside\n",
                method, steps, fluid, boundary, closest, furthest_left, most_inside);
    EXPECT_LT(closest, 0.02) << method;              // it reached the block (the test could fail)
    EXPECT_LT(furthest_left, kX0 + 0.06) << method;  // and went over the low step onto the high one or beyond
  }
}

bool bit_identical(const ParticleSet<double>& a, const ParticleSet<double>& b) {
  if (a.size() != b.size() || a.id != b.id) return false;
  const auto fa = a.fields(), fb = b.fields();
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      if (std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(double)) != 0) return false;
  const auto ia = a.int_fields(), ib = b.int_fields();
  for (std::size_t f = 0; f < ia.size(); ++f)
    if (std::memcmp(ia[f].data[0], ib[f].data[0], a.size() * sizeof(std::int32_t)) != 0) return false;
  return fa.size() == fb.size() && ia.size() == ib.size();
}

TEST_F(MeshBoundary, OneAndTwoThreadsAndAResumeGiveTheSameBits) {
  const int before = parallel::thread_count();
  const auto run = [&](int threads, int steps) {
    parallel::set_thread_count(threads);
    Simulation<double> sim = build("dfsph", 0.004);
    sim.start();
    for (int s = 0; s < steps; ++s) sim.step();
    return sim;
  };
  const Simulation<double> one = run(1, 40), two = run(2, 40);
  EXPECT_TRUE(bit_identical(one.particles(), two.particles()));
  Simulation<double> first = run(2, 15);
  Simulation<double> second = build("dfsph", 0.004);
  second.prepare();
  second.particles() = first.particles();
  NamedValues state;
  first.save_state(state);
  second.resume(first.clock(), state);
  for (int s = 0; s < 25; ++s) second.step();
  EXPECT_TRUE(bit_identical(one.particles(), second.particles()));
  parallel::set_thread_count(before);
}

}  // namespace
