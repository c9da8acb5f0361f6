// Inlets and outlets (sim/inlets_outlets.hpp; docs/sph.md, Fluid fills,
// inlets and outlets): an inlet emits its layer every spacing/speed (the
// count within one layer of rate × time), with fresh ids and its mass; an
// outlet removes every fluid particle inside it and nothing else; mass is
// the sum of what is left; runs on one and two threads, and one stopped and
// resumed, write the same frames and checkpoints byte for byte; the scene's
// refusals name the key; several MPI ranks are not refused (run_on_ranks.sh
// compares them with one rank).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sim/inlets_outlets.hpp"
#include "swirl/sim/run.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;
namespace fs = std::filesystem;

// A DFSPH tank 0.2 × 0.2 × 0.3 m: a layer of water 4 cm deep (200 particles), an
// inlet 5 cm wide pouring down at 1 m/s from z = 0.25, and `more`.
std::string tank(std::string_view more, std::uint64_t steps = 60) {
  return fmt::format(R"(
[simulation]
precision = "double"
dt = 0.001
steps = {steps}
block_size = 64

[box]
min = [0.0, 0.0, 0.0]
max = [0.2, 0.2, 0.3]

[forces]
gravity = [0.0, 0.0, -9.81]

[sph]
smoothing_length = 0.04
rest_density = 1000.0
viscosity = 0.1
method = "dfsph"

[output]
interval = 0.02

[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [0.2, 0.2, 0.04]
spacing = 0.02

[[inlets]]
center = [0.1, 0.1, 0.25]
direction = [0, 0, -2]
radius = 0.05
speed = 1.0
spacing = 0.02
{more}
)",
                     fmt::arg("steps", steps), fmt::arg("more", more));
}

class Folder {
 public:
  explicit Folder(std::string_view name)
      : path_(fs::temp_directory_path() / fmt::format("swirl-inlets-{}-{}", ::getpid(), name)) {
    fs::remove_all(path_);
  }
  ~Folder() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

sim::RunSummary run(const std::string& text, const fs::path& out, int threads, std::optional<std::uint64_t> steps = {},
                    bool resume = false, std::optional<std::uint64_t> checkpoint_every_steps = {}) {
  sim::RunOptions options;
  options.out_dir = out;
  options.threads = threads;
  options.steps = steps;
  options.resume = resume;
  options.checkpoint_every_steps = checkpoint_every_steps;
  return sim::run_scene(scene::parse_scene(text, "scene.toml"), options);
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

double metric(const sim::RunSummary& s, std::string_view name) {
  for (const auto& [k, v] : s.metrics)
    if (k == name) return v;
  ADD_FAILURE() << "no metric " << name;
  return -1;
}

std::string error_of(const std::string& text) {
  try {
    (void)scene::parse_scene(text, "scene.toml");
  } catch (const scene::SceneError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(Inlets, ALayerLeavesEverySpacingOverSpeedWithFreshIdsAndTheFluidsMass) {
  const scene::Scene s = scene::parse_scene(tank(""), "scene.toml");
  const std::size_t layer = sim::inlet_pattern(s.inlets[0]).size();
  // The points of a 5 × 5 square of spacing 0.02 strictly within 0.05: all but the 4 corners.
  EXPECT_EQ(layer, 21u);
  EXPECT_NEAR(double(layer), std::numbers::pi * 0.05 * 0.05 / (0.02 * 0.02), 0.1 * double(layer));
  Simulation<double> sim = sim::build_simulation<double>(s);
  sim.start();
  sim::InletsAndOutlets<double> inlets(s);
  inlets.on_start(sim, false);
  const std::size_t n0 = sim.particles().size();
  EXPECT_EQ(n0, 200u);
  const double block_mass = sim.particles().mass[0];
  for (int k = 0; k < 60; ++k) {
    sim.step();
    inlets.on_step(sim);
    // Layers at t = 0, 0.02, 0.04, ...: rate = 21 particles per 0.02 s, within one layer.
    const double expected = double(layer) * (sim.time() * 1.0 / 0.02 + 1);
    EXPECT_LE(std::abs(double(inlets.emitted()) - expected), double(layer)) << "t = " << sim.time();
  }
  EXPECT_GE(inlets.emitted(), 3u * layer);  // layers at 0, 0.02, 0.04 and (up to rounding of 0.06) 0.06
  EXPECT_LE(inlets.emitted(), 4u * layer);
  const auto& p = sim.particles();
  ASSERT_EQ(p.size(), n0 + inlets.emitted());
  std::set<std::uint64_t> ids(p.id.begin(), p.id.end());
  EXPECT_EQ(ids.size(), p.size());                         // no id twice
  EXPECT_EQ(*ids.rbegin(), p.size() - 1);                  // fresh ids: n0, n0 + 1, ...
  double mass = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    mass += p.mass[i];
    EXPECT_EQ(p.mass[i], block_mass) << i;  // the same spacing: the fluid_block's mass
    if (p.id[i] >= n0) {
      EXPECT_LT(p.velocity.z[i], 0.0) << "an entering particle moves down";
    }
  }
  EXPECT_NEAR(mass, double(p.size()) * block_mass, 1e-12 * mass);
}

// With boundary particles (a kind field) the fluid's count is what DFSPH's
// average errors divide by: it must follow the particles the inlet adds (it
// was once counted at the first evaluation only, so a fluid poured in was
// averaged over the fluid the run started with).
TEST(Inlets, TheFluidCountFollowsTheParticlesAdded) {
  std::string text = tank("", 40);
  text.replace(text.find("[box]\n"), 6, "[box]\nwalls = \"particles\"\n");
  const scene::Scene s = scene::parse_scene(text, "scene.toml");
  Simulation<double> sim = sim::build_simulation<double>(s);
  sim.start();
  sim::InletsAndOutlets<double> inlets(s);
  inlets.on_start(sim, false);
  const auto* fluid = sim.find_solver<sph::SphFluid<double>>();
  ASSERT_NE(fluid, nullptr);
  const auto fluid_now = [&] {
    std::size_t n = 0;
    const auto& p = sim.particles();
    const auto& kind = p.int_field(p.find_int_field(kKindField));
    for (std::size_t i = 0; i < p.size(); ++i) n += is_boundary(kind[i]) ? 0 : 1;
    return n;
  };
  EXPECT_EQ(fluid->fluid_count(sim.particles()), fluid_now());
  for (int k = 0; k < 40; ++k) {
    sim.step();
    inlets.on_step(sim);
  }
  ASSERT_GT(inlets.emitted(), 0u);
  EXPECT_EQ(fluid->fluid_count(sim.particles()), fluid_now());
  EXPECT_EQ(fluid_now(), 200u + inlets.emitted());
}

TEST(Outlets, RemoveEveryFluidParticleInsideAndNothingElse) {
  // No inlet: the outlet over the left half of the layer of water, walls of boundary particles.
  std::string text = tank("[[outlets]]\nmin = [-0.1, -0.1, -0.1]\nmax = [0.1, 0.3, 0.5]\n");
  text.replace(text.find("[[inlets]]"), text.find("[[outlets]]") - text.find("[[inlets]]"), "");
  text.replace(text.find("max = [0.2, 0.2, 0.3]"), 21, "max = [0.2, 0.2, 0.3]\nwalls = \"particles\"");
  const scene::Scene s = scene::parse_scene(text, "scene.toml");
  Simulation<double> sim = sim::build_simulation<double>(s);
  sim.start();
  sim::InletsAndOutlets<double> outlets(s);
  outlets.on_start(sim, false);
  const auto inside = [&](std::size_t i) { return s.outlets[0].region.contains(sim.particles().position.get(i)); };
  const std::size_t kind = sim.particles().find_int_field(kKindField);
  ASSERT_NE(kind, ParticleSet<double>::npos);
  const auto is_fluid = [&](std::size_t i) { return !is_boundary(sim.particles().int_field(kind)[i]); };
  sim.step();
  std::size_t fluid_in = 0, boundary_in = 0, n = sim.particles().size();
  for (std::size_t i = 0; i < n; ++i) (is_fluid(i) ? fluid_in : boundary_in) += inside(i) ? 1 : 0;
  EXPECT_EQ(fluid_in, 100u);
  EXPECT_GT(boundary_in, 0u);
  outlets.on_step(sim);
  EXPECT_EQ(outlets.removed(), fluid_in);
  EXPECT_EQ(sim.particles().size(), n - fluid_in);
  std::size_t fluid_after = 0, boundary_after = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) {
    EXPECT_FALSE(is_fluid(i) && inside(i)) << i;
    (is_fluid(i) ? fluid_after : boundary_after) += 1;
  }
  EXPECT_EQ(fluid_after, 100u);
  EXPECT_EQ(boundary_after, n - 200u);  // every boundary particle stays, inside the outlet too
  // Steps go on with the smaller set (the order and the solvers follow the count).
  for (int k = 0; k < 5; ++k) {
    sim.step();
    outlets.on_step(sim);
  }
  EXPECT_TRUE(std::isfinite(sim.particles().velocity.z[0]));
}

TEST(Inlets, WithoutInletsOrOutletsCountAndMassStay) {
  std::string text = tank("");
  text.replace(text.find("[[inlets]]"), std::string::npos, "");
  Folder out("plain");
  const sim::RunSummary r = run(text, out.path(), 1);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.particles, 200u);
  EXPECT_EQ(r.particles_end, 200u);
}

// Frames and checkpoints of runs whose count changes: one thread against
// two, and stopped at step 30 and resumed from its last checkpoint (at 25,
// between two layers; at 20, the step the second layer is added and the
// outlet takes water), byte for byte.
TEST(Inlets, OneAndTwoThreadsAndAResumeWriteTheSameBytes) {
  const std::string text = tank("[[outlets]]\nmin = [0.0, 0.0, -0.1]\nmax = [0.05, 0.2, 0.1]\n");
  for (const std::uint64_t every : {25u, 20u}) {
    Folder one(fmt::format("one{}", every)), two(fmt::format("two{}", every)), stopped(fmt::format("stopped{}", every));
    const sim::RunSummary a = run(text, one.path(), 1, {}, false, every);
    ASSERT_TRUE(a.error.empty()) << a.error;
    EXPECT_EQ(a.particles, 200u);
    EXPECT_EQ(a.particles_end,
              200u + std::size_t(metric(a, "inlet_particles")) - std::size_t(metric(a, "outlet_particles")));
    EXPECT_GT(metric(a, "inlet_particles"), 0);
    EXPECT_GT(metric(a, "outlet_particles"), 0);
    ASSERT_TRUE(run(text, two.path(), 2, {}, false, every).error.empty());
    ASSERT_TRUE(run(text, stopped.path(), 2, 30, false, every).error.empty());
    const sim::RunSummary resumed = run(text, stopped.path(), 1, 60 - every, true, every);
    ASSERT_TRUE(resumed.error.empty()) << resumed.error;
    EXPECT_EQ(resumed.particles_end, a.particles_end);
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(one.path()))
      if (e.path().extension() == ".vtp") files.push_back(e.path().filename());
    for (const auto& e : fs::directory_iterator(one.path() / "checkpoints"))
      files.push_back(fs::path("checkpoints") / e.path().filename());
    ASSERT_GE(files.size(), 4u + 2u);  // frames at t = 0, 0.02, 0.04, 0.06; two checkpoints or more
    std::size_t resumed_files = 0;
    for (const auto& f : files) {
      const std::string bytes = slurp(one.path() / f);
      EXPECT_EQ(bytes, slurp(two.path() / f)) << f;
      // The resumed run's frames, and its checkpoints after the stop (the
      // stopped run's own say that it ends at step 30).
      const bool checkpoint = f.parent_path() == "checkpoints";
      if (checkpoint && std::stoull(f.stem().string().substr(11)) <= 30) continue;
      ++resumed_files;
      if (fs::exists(stopped.path() / f)) {
        EXPECT_EQ(bytes, slurp(stopped.path() / f)) << "resumed " << f;
      } else {
        ADD_FAILURE() << "the resumed run has no " << f;
      }
    }
    EXPECT_GE(resumed_files, 5u) << every;
  }
}

TEST(Inlets, BadKeysAreRefusedNamingTheKey) {
  const auto refused = [](const std::string& text, std::string_view key, std::string_view reason) {
    const std::string e = error_of(text);
    EXPECT_NE(e.find("scene.toml"), std::string::npos) << e;
    EXPECT_NE(e.find(key), std::string::npos) << e;
    EXPECT_NE(e.find(reason), std::string::npos) << e;
  };
  const std::string ok = tank("");
  const auto with = [&](std::string_view from, std::string_view to) {  // the last `from`: the inlet's
    std::string t = ok;
    t.replace(t.rfind(from), from.size(), to);
    return t;
  };
  refused(with("radius = 0.05", "radius = -0.05"), "inlets[0].radius", "> 0");
  refused(with("direction = [0, 0, -2]", "direction = [0, 0, 0]"), "inlets[0].direction", "must not be zero");
  refused(with("speed = 1.0", "speed = 1.0\nstart = 0.5\nstop = 0.5"), "inlets[0].stop", "greater than");
  refused(with("center = [0.1, 0.1, 0.25]", "center = [0.1, 0.1, 0.35]"), "inlets[0].center", "outside the box");
  refused(with("speed = 1.0", "sped = 1.0"), "inlets[0].sped", "unknown key");
  refused(with("spacing = 0.02\n", ""), "inlets[0].spacing", "missing");
  refused(tank("[[outlets]]\nmin = [0.1, 0, 0]\nmax = [0.1, 0.2, 0.2]\n"), "outlets[0].max", "greater than");
  refused(tank("[[outlets]]\nmax = [0.1, 0.2, 0.2]\n"), "outlets[0].min", "missing");
}

// On several ranks (tests/dist/run_on_ranks.sh runs them against one rank).
TEST(Inlets, RunOnSeveralMpiRanks) {
  const std::string no = sim::distributed_support(scene::parse_scene(tank(""), "scene.toml"));
  EXPECT_EQ(no, "");
}

}  // namespace
