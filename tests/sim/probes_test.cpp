// Probes (probes.csv; docs/sph.md, Probes; sph/probes.hpp, src/sim/probe_log.hpp):
// a hydrostatic tank's pressure probe, water-height gauge and the force of
// the fluid on its walls and floor against hydrostatics; probes.csv across a
// resume and on one and two threads; the scene's refusals.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sim/run.hpp"
#include "swirl/sph/probes.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace {

using namespace swirl;
namespace fs = std::filesystem;

// A tank L × L × 0.3 m with walls of particles, water `depth` deep at spacing
// 0.02, DFSPH with a tight density tolerance (its κ is the pressure), `more`
// appended (probes, obstacles).
std::string tank(double L, double depth, double end_time, std::string_view more) {
  return fmt::format(R"(
[simulation]
precision = "double"
dt = 0.005
end_time = {end}
block_size = 64

[box]
min = [0.0, 0.0, 0.0]
max = [{L}, {L}, 0.3]
walls = "particles"

[forces]
gravity = [0.0, 0.0, -9.81]

[sph]
neighbours = 30
rest_density = 1000.0
viscosity = 0.5
method = "dfsph"

[sph.dfsph]
density_tolerance = 2e-4

[output]
interval = 1.0
probes_interval = 0.025
obstacle_forces = true

[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [{L}, {L}, {depth}]
spacing = 0.02
{more}
)",
                     fmt::arg("end", end_time), fmt::arg("L", L), fmt::arg("depth", depth), fmt::arg("more", more));
}

// `text` with its first `from` replaced by `to` (which must be there).
std::string swap(std::string text, std::string_view from, std::string_view to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) throw std::logic_error(fmt::format("'{}' is not in the scene", from));
  return text.replace(at, from.size(), to);
}

class Folder {
 public:
  explicit Folder(std::string_view name)
      : path_(fs::temp_directory_path() / fmt::format("swirl_probes_{}_{}", name, ::getpid())) {
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

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::size_t column(std::string_view name) const {
    for (std::size_t k = 0; k < header.size(); ++k)
      if (header[k] == name) return k;
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
};

Csv read_csv(const fs::path& file) {
  Csv csv;
  std::istringstream in(io::read_text_file(file));
  std::string line;
  std::getline(in, line);
  std::stringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) csv.header.push_back(cell);
  while (std::getline(in, line)) {
    std::stringstream r(line);
    std::vector<double> row;
    for (std::string cell; std::getline(r, cell, ',');) row.push_back(std::stod(cell));
    csv.rows.push_back(row);
  }
  return csv;
}

constexpr double kG = 9.81, kRho0 = 1000;

sph::SphFluid<double>& fluid_of(Simulation<double>& sim) {
  for (const auto& s : sim.solvers())
    if (auto* f = dynamic_cast<sph::SphFluid<double>*>(s.get())) return *f;
  throw std::logic_error("no SPH solver");
}

// 0.12 × 0.12 m of water 0.2 m deep (360 particles) at rest from t = 0:
// DFSPH holds it up from the first step, and its column rings down over a
// few tenths of a second. Rows from 0.2 s to 0.6 s are averaged.
TEST(ProbesHydrostatic, PressureHeightAndTheWallsForceAgreeWithHydrostatics) {
  const double L = 0.12, depth = 0.2, s = 0.02;
  Folder out("tank");
  const auto summary = run(tank(L, depth, 0.6, R"(
[[probes]]
name = "deep"
point = [0.06, 0.06, 0.1]

[[probes]]
name = "gauge"
line = [[0.06, 0.06, 0.0], [0.06, 0.06, 0.3]]

[[probes]]
name = "dry"
point = [0.06, 0.06, 0.28]
)"),
                           out.path(), 2);
  ASSERT_TRUE(summary.error.empty()) << summary.error;
  const Csv csv = read_csv(out.path() / "probes.csv");
  ASSERT_EQ(csv.header.size(), 1u + 3u + 6u);
  EXPECT_EQ(csv.header[0], "time");
  const std::size_t p = csv.column("deep_pressure"), h = csv.column("gauge_height"), dry = csv.column("dry_pressure");
  const std::size_t fz = csv.column("walls_force_z");
  ASSERT_EQ(csv.rows.size(), 25u);  // t = 0, 0.025, ..., 0.6
  const double weight = kRho0 * L * L * depth * kG;  // 28.25 N
  double pressure = 0, height = 0, force = 0, torque = 0, force_xy = 0;
  int n = 0;
  for (const auto& row : csv.rows) {
    EXPECT_EQ(row[dry], 0.0);  // no fluid within h of it
    if (row[0] < 0.2 - 1e-9) continue;
    ++n;
    pressure += row[p], height += row[h], force += row[fz];
    // Every gauge reading after 0.2 s within one spacing of the depth.
    EXPECT_NEAR(row[h], depth, s) << "t = " << row[0];
    for (const char* q : {"walls_torque_x", "walls_torque_y", "walls_torque_z"})
      torque = std::max(torque, std::abs(row[csv.column(q)]));
    for (const char* q : {"walls_force_x", "walls_force_y"}) force_xy = std::max(force_xy, std::abs(row[csv.column(q)]));
  }
  pressure /= n, height /= n, force /= n;
  const double expected = kRho0 * kG * 0.1;
  std::printf("tank: p(depth 0.1) = %.1f Pa (rho0 g d = %.1f), height %.4f m, walls F_z %.3f N (weight %.3f N), "
              "|torque| <= %.3g N m, |F_xy| <= %.3g N\n",
              pressure, expected, height, force, weight, torque, force_xy);
  // Measured (2026-12-03): p̄ = 942.7 Pa, −3.9 % of ρ0 g d for the nominal
  // d = 0.1 m, −0.6 % for the depth below the gauge's mean surface (0.0967 m);
  // h̄ = 0.1967 m (the settled surface is s/6 below the lattice's 0.2 m);
  // F̄_z = −28.30 N against a weight of 28.25 N (+0.2 %); |τ| ≤ 1.2e-3 N·m.
  // The tolerances: 5 %, a quarter spacing, 2 %, and 1e-3 of the scales.
  EXPECT_NEAR(pressure, expected, 0.05 * expected);
  EXPECT_NEAR(height, depth, s / 4);
  EXPECT_NEAR(force, -weight, 0.02 * weight);
  // A symmetric tank: no torque about its centre, no sideways force (to a
  // thousandth of the weight, and of its moment over the tank's size).
  EXPECT_LT(torque, 1e-3 * weight * L);
  EXPECT_LT(force_xy, 1e-3 * weight);
}

// The floor (the walls' particles below z = 0) under hydrostatics, through
// the Simulation API and SphFluid::boundary_forces, averaged over 0.2–0.35 s
// in a 0.16 × 0.16 m tank. Away from the side walls (its particles more than
// h from them) each floor particle carries the water column above its share
// of the floor, ρ0 g H s_x s_y. The floor as a whole carries more than the
// weight, and the side walls are pushed up: Akinci's pair uses the fluid
// particle's own pressure, so a wall particle with more pressure below it
// than above (beside the water, in its gradient) is pushed along −∇p, and the
// fluid's bottom layer pushes the side walls' lowest rows up while the
// matching push down lands on the floor's edge rows. Only the sum over all the
// walls is the weight (the previous test). Measured (2026-12-03): the 16
// central floor particles −12.99 N against a column of 13.04 N (−0.4 %); the
// whole floor −54.38 N, the side walls +4.17 N, the weight 50.23 N.
TEST(ProbesHydrostatic, TheFloorCarriesTheWaterColumnAboveIt) {
  const double L = 0.16, depth = 0.2;
  const scene::Scene sc = scene::parse_scene(tank(L, depth, 0.35, ""), "scene.toml");
  Simulation<double> sim = sim::build_simulation<double>(sc);
  sim.start();
  sph::SphFluid<double>& fluid = fluid_of(sim);
  fluid.record_boundary_reactions(true);  // as probes.csv has it
  const double h = sc.sph->smoothing_length;
  std::vector<double> f;
  double floor = 0, sides = 0, patch = 0;
  std::size_t patch_count = 0;
  int n = 0;
  for (int k = 1; k <= 70; ++k) {
    sim.step();
    if (k < 40) continue;
    const ParticleSet<double>& p = sim.particles();
    const std::int32_t* kind = p.int_field(p.find_int_field(kKindField)).data();
    fluid.boundary_forces(p, 64, f);
    patch_count = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!is_boundary(kind[i])) {
        EXPECT_EQ(f[3 * i] + f[3 * i + 1] + f[3 * i + 2], 0.0);
        continue;
      }
      const double x = p.position.x[i], y = p.position.y[i];
      (p.position.z[i] < 0 ? floor : sides) += f[3 * i + 2];
      if (p.position.z[i] < 0 && x > h && x < L - h && y > h && y < L - h) {
        patch += f[3 * i + 2];
        ++patch_count;
      }
    }
    ++n;
  }
  floor /= n, sides /= n, patch /= n;
  // The floor's spacing: the grown box's side in round(side/s) intervals (scene/initial_conditions.hpp).
  const double grown = L + 2 * scene::wall_offset(sc), step = grown / std::round(grown / 0.02);
  const double column = kRho0 * kG * depth * double(patch_count) * step * step;
  const double weight = kRho0 * L * L * depth * kG;
  std::printf("floor: %zu central particles F_z %.3f N (column %.3f N); whole floor %.3f N, side walls %.3f N, weight "
              "%.3f N\n",
              patch_count, patch, column, floor, sides, weight);
  ASSERT_GE(patch_count, 16u);
  EXPECT_NEAR(patch, -column, 0.03 * column);
  EXPECT_NEAR(floor + sides, -weight, 0.02 * weight);
}

// The thesis's solver: its pair law is antisymmetric between fluid
// particles, so Σ_fluid m a = M g + the walls' push on the fluid, and the
// reaction boundary_forces() sums must be minus that push, at every step, to
// rounding (without viscosity, whose reaction uses the velocity after the
// kick while the evaluation used the one before it). The column rings (it
// starts at rest density, without pressure), so its momentum changes: the
// balance, not the weight, is what holds at each step.
TEST(ProbesHydrostatic, TheThesisSolversReactionBalancesTheFluidsMomentum) {
  const double L = 0.12, depth = 0.2;
  std::string text = swap(tank(L, depth, 0.05, ""), "method = \"dfsph\"", "method = \"wcsph\"\nsound_speed = 20.0");
  text = swap(text, "[sph.dfsph]\ndensity_tolerance = 2e-4\n", "");
  text = swap(text, "dt = 0.005", "dt = 0.0005");
  text = swap(text, "viscosity = 0.5", "viscosity = 0.0");
  Simulation<double> sim = sim::build_simulation<double>(scene::parse_scene(text, "scene.toml"));
  sim.start();
  sph::SphFluid<double>& fluid = fluid_of(sim);
  const double weight = kRho0 * L * L * depth * kG;
  std::vector<double> f;
  double worst = 0, largest = 0;
  for (int k = 1; k <= 100; ++k) {
    sim.step();
    const ParticleSet<double>& p = sim.particles();
    const std::int32_t* kind = p.int_field(p.find_int_field(kKindField)).data();
    fluid.boundary_forces(p, 64, f);
    std::array<double, 3> balance{};  // Σ_b F_b + Σ_fluid m (a − g)
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int axis = 0; axis < 3; ++axis) balance[static_cast<std::size_t>(axis)] += f[3 * i + static_cast<std::size_t>(axis)];
      if (!is_boundary(kind[i])) {
        balance[0] += p.mass[i] * p.acceleration.x[i];
        balance[1] += p.mass[i] * p.acceleration.y[i];
        balance[2] += p.mass[i] * (p.acceleration.z[i] + kG);
      }
    }
    double fz = 0;
    for (std::size_t i = 0; i < p.size(); ++i) fz += f[3 * i + 2];
    largest = std::max(largest, std::abs(fz));
    for (const double b : balance) worst = std::max(worst, std::abs(b));
  }
  std::printf("thesis's solver: |walls' reaction + fluid's m (a - g)| <= %.3g N (walls' |F_z| up to %.3g N, weight "
              "%.3g N)\n",
              worst, largest, weight);
  EXPECT_LT(worst, 1e-9 * weight);
  EXPECT_GT(largest, 0.5 * weight);  // the walls did hold the column
}

// DFSPH: the fluid's momentum changes over a step by Δt (M g − Σ_b F_b) when
// F_b are the walls' reactions to the step's two pressure impulses (the
// constant-density solve's recorded at the step's start, the divergence-free
// solve's at its end): checked at every step to rounding, without viscosity
// (whose next-step term is computed from the final velocities).
TEST(ProbesHydrostatic, DfsphReactionBalancesTheFluidsMomentumChange) {
  const double L = 0.12, depth = 0.2, dt = 0.005;
  const std::string text = swap(tank(L, depth, 0.2, ""), "viscosity = 0.5", "viscosity = 0.0");
  Simulation<double> sim = sim::build_simulation<double>(scene::parse_scene(text, "scene.toml"));
  sim.start();
  sph::SphFluid<double>* fluid = &fluid_of(sim);
  fluid->record_boundary_reactions(true);
  const auto momentum = [&] {
    const ParticleSet<double>& p = sim.particles();
    std::array<double, 3> m{};
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int axis = 0; axis < 3; ++axis) m[static_cast<std::size_t>(axis)] += p.mass[i] * p.velocity[axis][i];
    return m;
  };
  double fluid_mass = 0;
  {
    const ParticleSet<double>& p = sim.particles();
    const std::int32_t* kind = p.int_field(p.find_int_field(kKindField)).data();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!is_boundary(kind[i])) fluid_mass += p.mass[i];
  }
  std::vector<double> f;
  double worst = 0, largest = 0;
  for (int k = 1; k <= 40; ++k) {
    const auto before = momentum();
    sim.step();
    const auto after = momentum();
    fluid->boundary_forces(sim.particles(), 64, f);
    std::array<double, 3> walls{};
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      for (std::size_t axis = 0; axis < 3; ++axis) walls[axis] += f[3 * i + axis];
    const std::array<double, 3> g{0, 0, -kG};
    for (std::size_t axis = 0; axis < 3; ++axis)
      worst = std::max(worst, std::abs((after[axis] - before[axis]) / dt - fluid_mass * g[axis] + walls[axis]));
    largest = std::max(largest, std::abs(walls[2]));
  }
  const double weight = fluid_mass * kG;
  std::printf("DFSPH: |dP/dt - M g + walls' reaction| <= %.3g N (walls' |F_z| up to %.3g N, weight %.3g N)\n", worst,
              largest, weight);
  EXPECT_LT(worst, 1e-9 * weight);
  EXPECT_GT(largest, 0.5 * weight);
}

// A dam break against a named cylinder, DFSPH: probes.csv of a run stopped
// at step 30 (checkpoint at 25) and resumed to 60 on two threads is the
// uninterrupted one-thread run's, byte for byte.
TEST(ProbesFile, ResumedAndTwoThreadRunsWriteTheSameBytes) {
  const std::string scene = fmt::format(R"(
[simulation]
precision = "double"
dt = 0.002
steps = 60
block_size = 64

[box]
min = [0.0, 0.0, 0.0]
max = [0.4, 0.1, 0.3]
walls = "particles"

[forces]
gravity = [0.0, 0.0, -9.81]

[sph]
neighbours = 30
rest_density = 1000.0
viscosity = 0.1
method = "dfsph"

[output]
interval = 1.0
probes_interval = 0.01
obstacle_forces = true

[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [0.12, 0.1, 0.2]
spacing = 0.025

[[particles]]
kind = "obstacle_cylinder"
name = "pillar"
start = [0.25, 0.0, 0.05]
end = [0.25, 0.1, 0.05]
radius = 0.04

[[probes]]
name = "p"
point = [0.05, 0.05, 0.05]

[[probes]]
name = "h"
line = [[0.1, 0.05, 0.0], [0.1, 0.05, 0.3]]
)");
  Folder straight("straight"), stopped("stopped");
  ASSERT_TRUE(run(scene, straight.path(), 1).error.empty());
  ASSERT_TRUE(run(scene, stopped.path(), 2, 30, false, 25).error.empty());
  const Csv first = read_csv(stopped.path() / "probes.csv");
  ASSERT_EQ(first.rows.size(), 7u);  // t = 0, 0.01, ..., 0.06 (steps 0, 5, ..., 30)
  ASSERT_TRUE(run(scene, stopped.path(), 2, 35, true).error.empty());
  const std::string a = io::read_text_file(straight.path() / "probes.csv");
  const std::string b = io::read_text_file(stopped.path() / "probes.csv");
  EXPECT_EQ(a, b);
  const Csv csv = read_csv(straight.path() / "probes.csv");
  EXPECT_EQ(csv.header.size(), 1u + 2u + 12u);
  EXPECT_EQ(csv.header[3], "pillar_force_x");
  EXPECT_EQ(csv.header[9], "walls_force_x");
  EXPECT_EQ(csv.rows.size(), 13u);  // t = 0, 0.01, ..., 0.12
  // The water reached the pillar and pushes it along +x by the end.
  EXPECT_GT(csv.rows.back()[csv.column("pillar_force_x")], 0.0);
}

// ---- Refusals ----------------------------------------------------------------

std::string refusal(const std::string& more, std::string_view output = "obstacle_forces = true") {
  const std::string text = swap(tank(0.12, 0.2, 0.1, more), "obstacle_forces = true", output);
  try {
    scene::parse_scene(text, "tank.toml");
  } catch (const scene::SceneError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ProbesScene, BadProbesAreRefusedNamingTheFileTheKeyAndTheReason) {
  const auto expect = [](const std::string& message, std::vector<std::string_view> parts) {
    EXPECT_NE(message.find("tank.toml"), std::string::npos) << message;
    for (const auto part : parts) EXPECT_NE(message.find(part), std::string::npos) << message << "\n  lacks: " << part;
  };
  expect(refusal("[[probes]]\nname = \"a\"\npoint = [0.06, 0.06, 0.5]\n"), {"probes[0].point", "outside the box"});
  expect(refusal("[[probes]]\nname = \"a\"\nline = [[0.06, 0.06, 0.0], [0.07, 0.06, 0.3]]\n"),
         {"probes[0].line", "must be vertical"});
  expect(refusal("[[probes]]\nname = \"a\"\nline = [[0.06, 0.06, 0.3], [0.06, 0.06, 0.0]]\n"),
         {"probes[0].line", "lower end"});
  expect(refusal("[[probes]]\nname = \"a\"\nline = [[0.06, 0.06, 0.0]]\n"), {"probes[0].line", "two points"});
  expect(refusal("[[probes]]\nname = \"a\"\npoint = [0.06, 0.06, 0.1]\nradius = 2\n"),
         {"probes[0].radius", "unknown key"});
  expect(refusal("[[probes]]\nname = \"a\"\npiont = [0.06, 0.06, 0.1]\n"), {"probes[0].piont", "did you mean 'point'"});
  expect(refusal("[[probes]]\nname = \"a\"\n"), {"probes[0].point", "missing"});
  expect(refusal("[[probes]]\npoint = [0.06, 0.06, 0.1]\n"), {"probes[0].name", "missing"});
  expect(refusal("[[probes]]\nname = \"a\"\npoint = [0.06, 0.06, 0.1]\nline = [[0.06, 0.06, 0.0], [0.06, 0.06, 0.3]]\n"),
         {"probes[0].line", "cannot be given together"});
  expect(refusal("[[probes]]\nname = \"a\"\npoint = [0.06, 0.06, 0.1]\n[[probes]]\nname = \"a\"\npoint = [0.06, 0.06, "
                 "0.2]\n"),
         {"probes[1].name", "'a' is already taken by probes[0].name"});
  expect(refusal("[[probes]]\nname = \"walls\"\npoint = [0.06, 0.06, 0.1]\n"), {"probes[0].name", "already taken"});
  expect(refusal("[[probes]]\nname = \"a b\"\npoint = [0.06, 0.06, 0.1]\n"), {"probes[0].name", "letters, digits"});
  expect(refusal("[[particles]]\nkind = \"obstacle_sphere\"\ncenter = [0.06, 0.06, 0.25]\nradius = 0.02\nname = \"x,y\"\n"),
         {"particles[1].name", "letters, digits"});
  // Without boundary particles there is nothing to measure a force on.
  const std::string clamp = swap(tank(0.12, 0.2, 0.1, ""), "walls = \"particles\"", "walls = \"clamp\"");
  try {
    scene::parse_scene(clamp, "tank.toml");
    ADD_FAILURE() << "accepted";
  } catch (const scene::SceneError& e) {
    expect(e.what(), {"output.obstacle_forces", "no boundary particles"});
  }
}

// Scenes without probes keep their hash (checkpoints from before probes still resume).
TEST(ProbesScene, ScenesWithoutProbesKeepTheirHash) {
  const std::string without = swap(tank(0.12, 0.2, 0.1, ""), "probes_interval = 0.025\nobstacle_forces = true\n", "");
  const std::uint64_t base = scene::scene_hash(scene::parse_scene(without, "tank.toml"));
  const std::string defaults =
      swap(without, "interval = 1.0\n", "interval = 1.0\nprobes_interval = 0\nobstacle_forces = false\n");
  EXPECT_EQ(scene::scene_hash(scene::parse_scene(defaults, "tank.toml")), base);
  EXPECT_NE(scene::scene_hash(scene::parse_scene(
                without + "[[probes]]\nname = \"a\"\npoint = [0.06, 0.06, 0.1]\n", "tank.toml")),
            base);
}

// On several ranks rank 0 evaluates the probes over the particles the ranks
// chose with reaches_point / reaches_line (src/sim/probe_log.hpp): those must
// be every particle that adds to a probe, so that the sums over them, in the
// same order, are the sums over the whole set bit for bit. A cloud of water
// particles (random, with random densities and pressures) around a point and
// a line, the thesis's kernel and DFSPH's cubic spline, float and double.
template <class Real>
void reaching_particles_give_the_whole_sets_bits(sph::SphKernel kernel) {
  sph::SphParameters params;
  params.smoothing_length = 0.04;
  params.method = kernel == sph::SphKernel::Thesis ? sph::SphMethod::Wcsph : sph::SphMethod::Dfsph;
  params.kernel = kernel;
  const sph::ProbeSampler sampler(params);
  const Vec3d point{0.1, 0.1, 0.1}, lower{0.12, 0.08, 0.0}, upper{0.12, 0.08, 0.2};
  const std::size_t n = 4000;
  ParticleSet<Real> all(n);
  std::uint64_t state = 12345;
  auto uniform = [&state] {  // a fixed LCG: the same cloud on every machine
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / double(1ULL << 53);
  };
  for (std::size_t j = 0; j < n; ++j) {
    all.position.set(j, Vec3<Real>{Real(0.2 * uniform()), Real(0.2 * uniform()), Real(0.15 * uniform())});
    all.mass[j] = Real(0.02 * (0.9 + 0.2 * uniform()));
    all.density[j] = Real(1000 * (0.95 + 0.1 * uniform()));
    all.pressure[j] = Real(500 * uniform());
  }
  ParticleSet<Real> near_point(0), near_line(0);
  std::vector<std::size_t> pj, lj;
  for (std::size_t j = 0; j < n; ++j) {
    if (sampler.reaches_point(all, j, point)) pj.push_back(j);
    if (sampler.reaches_line(all, j, lower, upper)) lj.push_back(j);
  }
  auto subset = [&](const std::vector<std::size_t>& js) {
    ParticleSet<Real> s(js.size());
    for (std::size_t k = 0; k < js.size(); ++k) {
      s.position.set(k, all.position.get(js[k]));
      s.mass[k] = all.mass[js[k]], s.density[k] = all.density[js[k]], s.pressure[k] = all.pressure[js[k]];
    }
    return s;
  };
  near_point = subset(pj), near_line = subset(lj);
  // The cloud reaches well beyond h of the probes, and each has neighbours.
  ASSERT_GT(pj.size(), 20u);
  ASSERT_LT(pj.size(), n / 10);
  ASSERT_GT(lj.size(), 100u);
  ASSERT_LT(lj.size(), n / 3);
  const double p = sampler.pressure(all, point), h = sampler.height(all, lower, upper);
  EXPECT_GT(p, 0);
  EXPECT_GT(h, 0);
  EXPECT_LT(h, upper.z - lower.z);  // the cloud's top is inside the line
  EXPECT_EQ(std::bit_cast<std::uint64_t>(sampler.pressure(near_point, point)), std::bit_cast<std::uint64_t>(p));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(sampler.height(near_line, lower, upper)), std::bit_cast<std::uint64_t>(h));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(sampler.colour(near_point, point)),
            std::bit_cast<std::uint64_t>(sampler.colour(all, point)));
}

TEST(ProbeSampler, TheParticlesThatReachAProbeGiveTheWholeSetsBits) {
  reaching_particles_give_the_whole_sets_bits<float>(sph::SphKernel::Thesis);
  reaching_particles_give_the_whole_sets_bits<double>(sph::SphKernel::Thesis);
  reaching_particles_give_the_whole_sets_bits<float>(sph::SphKernel::CubicSpline);
  reaching_particles_give_the_whole_sets_bits<double>(sph::SphKernel::CubicSpline);
}

}  // namespace
