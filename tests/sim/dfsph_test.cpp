// Divergence-free SPH (sph.method = "dfsph"; sph/dfsph_stepper.hpp): a column
// at rest settles, the dam break keeps its density within 0.1 % at a step five
// times the thesis's solver's, any thread count and a resume give the same
// bits, and a solve that cannot converge stops the run with its cause.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sph/dfsph_stepper.hpp"

namespace {

using namespace swirl;

// A water column of w × d × H (spacing s) at the low-x end of a box of L × d × 0.6, SI units.
std::string column_scene(double w, double d, double height, double length, double s, double dt, std::string_view method,
                         std::string_view extra = "") {
  return fmt::format(R"(
[simulation]
precision = "double"
dt = {dt}
steps = 1
block_size = 64

[box]
min = [0.0, 0.0, 0.0]
max = [{length}, {d}, 0.6]
restitution = 0.2

[forces]
gravity = [0.0, 0.0, -9.81]

[sph]
neighbours = 30
rest_density = 1000.0
sound_speed = 20.0
viscosity = 0.1
negative_pressure = "zero"
method = "{method}"
{extra}

[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [{w}, {d}, {height}]
spacing = {s}
jitter = 0.05
)",
                     fmt::arg("dt", dt), fmt::arg("length", length), fmt::arg("d", d), fmt::arg("method", method),
                     fmt::arg("extra", extra), fmt::arg("w", w), fmt::arg("height", height), fmt::arg("s", s));
}

Simulation<double> build(const std::string& text) {
  return sim::build_simulation<double>(scene::parse_scene(text, "scene.toml"));
}

// The average compression Σ_i max(ρ_i − ρ0, 0) / (N ρ0): the error DFSPH's
// density solve bounds, measured on each solver's own density of the state.
double mean_compression(const ParticleSet<double>& p, double rho0 = 1000) {
  double sum = 0;
  for (std::size_t i = 0; i < p.size(); ++i) sum += std::max(p.density[i] - rho0, 0.0);
  return sum / (double(p.size()) * rho0);
}

double kinetic_energy(const ParticleSet<double>& p) {
  double e = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double vx = p.velocity.x[i], vy = p.velocity.y[i], vz = p.velocity.z[i];
    e += 0.5 * p.mass[i] * (vx * vx + vy * vy + vz * vz);
  }
  return e;
}

bool bit_identical(const ParticleSet<double>& a, const ParticleSet<double>& b) {
  if (a.size() != b.size() || a.id != b.id) return false;
  const auto fa = a.fields(), fb = b.fields();
  if (fa.size() != fb.size()) return false;
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      if (std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(double)) != 0) return false;
  return true;
}

TEST(Dfsph, AColumnAtRestSettlesWithItsDensityWithinTheTolerance) {
  // 0.15 × 0.15 × 0.3 m at spacing 0.025 (432 particles) filling the box's floor.
  Simulation<double> sim = build(column_scene(0.15, 0.15, 0.3, 0.15, 0.025, 0.004, "dfsph"));
  sim.start();
  const auto& stepper = dynamic_cast<const sph::DfsphStepper<double>&>(sim.stepper());
  double total_mass = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) total_mass += sim.particles().mass[i];
  double peak = 0;
  for (int s = 0; s < 250; ++s) {  // 1 s
    sim.step();
    peak = std::max(peak, kinetic_energy(sim.particles()));
  }
  // m·g·H = 20 J for the column's 6.8 kg. Without wall particles the floor
  // layer is under-dense (half a kernel), so the column first sinks into it
  // (kinetic energy peaks near 0.8 J at 0.1 s) and then rings down: 0.025 J
  // at 1 s (measured), bounded here by 2.5e-3·m·g·H = 0.05 J and 10 % of the peak.
  const double scale = total_mass * 9.81 * 0.3;
  const double ke = kinetic_energy(sim.particles());
  EXPECT_LT(ke, 2.5e-3 * scale) << ke;
  EXPECT_LT(ke, 0.1 * peak) << ke << " " << peak;
  EXPECT_LE(stepper.last_density_solve().error, 5e-4);
  EXPECT_LE(stepper.last_divergence_solve().error, 1e-3);
  EXPECT_LT(mean_compression(sim.particles()), 1e-3);
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(sim.particles().position[a][i], 0.0);
      EXPECT_LE(sim.particles().position[a][i], a == 2 ? 0.6 : 0.15);
    }
}

// The thesis's solver against DFSPH on the same dam break (0.3 × 0.12 × 0.4 m
// at spacing 0.03 in a 1 m box, to t = 0.4 s): the average compression over
// the run and its largest value.
struct Measured {
  double mean = 0, worst = 0;
};
Measured dam_break(std::string_view method, double dt) {
  Simulation<double> sim = build(column_scene(0.3, 0.12, 0.4, 1.0, 0.03, dt, method));
  sim.start();
  Measured m;
  const int steps = int(std::lround(0.4 / dt));
  for (int s = 0; s < steps; ++s) {
    sim.step();
    const double c = mean_compression(sim.particles());
    m.mean += c / steps;
    m.worst = std::max(m.worst, c);
  }
  return m;
}

TEST(Dfsph, DamBreakKeepsTheDensityWithinATenthOfAPercentAtFiveTimesTheStep) {
  const double wcsph_dt = 4e-4, dfsph_dt = 5 * wcsph_dt;
  const Measured wcsph = dam_break("wcsph", wcsph_dt);
  const Measured dfsph = dam_break("dfsph", dfsph_dt);
  std::printf("dam break, average compression: wcsph (dt %g) mean %.4f %% worst %.4f %%; dfsph (dt %g) mean %.4f %% "
              "worst %.4f %%\n",
              wcsph_dt, 100 * wcsph.mean, 100 * wcsph.worst, dfsph_dt, 100 * dfsph.mean, 100 * dfsph.worst);
  // Measured: wcsph mean 0.34 %, worst 1.24 %; dfsph mean 0.0019 %, worst 0.0069 %.
  EXPECT_LE(dfsph.mean, 1e-3);
  EXPECT_LE(dfsph.worst, 1e-3);
  EXPECT_GE(wcsph.worst, 1e-2);
  EXPECT_GE(wcsph.mean, 5 * dfsph.mean);
}

// With dt = "adaptive" the CFL condition sets the step (up to 30 ms before
// the column moves); the solves hold their tolerances through the splash
// against the far wall. (Before α was capped, sph/dfsph_passes.hpp, a splash
// pair's factor blew this run up.)
TEST(Dfsph, AnAdaptiveStepCarriesTheDamBreakThroughItsSplash) {
  std::string text = column_scene(0.3, 0.12, 0.4, 1.0, 0.03, 0.1, "dfsph");
  text.replace(text.find("dt = 0.1"), 8, "dt = \"adaptive\"\ndt_max = 0.05");
  Simulation<double> sim = build(text);
  sim.start();
  const auto& stepper = dynamic_cast<const sph::DfsphStepper<double>&>(sim.stepper());
  while (sim.time() < 1.0) sim.step();
  NamedValues m;
  stepper.add_metrics(m);
  const auto metric = [&](std::string_view k) { return find_value(m, k).value_or(-1.0); };
  std::printf("adaptive dam break: %llu steps to t = 1 s, density iterations mean %.2f max %.0f, divergence mean %.2f "
              "max %.0f\n",
              static_cast<unsigned long long>(sim.step_count()), metric("dfsph_mean_density_iterations"),
              metric("dfsph_max_density_iterations"), metric("dfsph_mean_divergence_iterations"),
              metric("dfsph_max_divergence_iterations"));
  EXPECT_LE(metric("dfsph_max_density_error"), 5e-4);
  EXPECT_LE(metric("dfsph_max_divergence_error"), 1e-3);
  EXPECT_LT(mean_compression(sim.particles()), 1e-3);
}

// A breaking column (0.15 × 0.1 × 0.25 m, 240 particles in blocks of 64) after n steps of 2 ms.
Simulation<double> breaking(int threads, int steps) {
  const int before = parallel::thread_count();
  parallel::set_thread_count(threads);
  Simulation<double> sim = build(column_scene(0.15, 0.1, 0.25, 0.4, 0.025, 0.002, "dfsph"));
  sim.start();
  for (int s = 0; s < steps; ++s) sim.step();
  parallel::set_thread_count(before);
  return sim;
}

TEST(Dfsph, OneTwoAndThreeThreadsGiveTheSameBits) {
  const Simulation<double> one = breaking(1, 60);
  const Simulation<double> two = breaking(2, 60);
  const Simulation<double> three = breaking(3, 60);
  EXPECT_TRUE(bit_identical(one.particles(), two.particles()));
  EXPECT_TRUE(bit_identical(one.particles(), three.particles()));
  // The solves did work (the warm starts are part of the compared fields).
  const auto& stepper = dynamic_cast<const sph::DfsphStepper<double>&>(one.stepper());
  EXPECT_GE(stepper.last_density_solve().iterations, 2u);
}

// What a checkpoint keeps (every field, the warm starts among them, the clock
// and the stepper's state) continues bit-identically.
TEST(Dfsph, ResumingMidRunIsBitIdentical) {
  const Simulation<double> straight = breaking(2, 60);
  Simulation<double> first = breaking(2, 25);
  const std::string text = column_scene(0.15, 0.1, 0.25, 0.4, 0.025, 0.002, "dfsph");
  Simulation<double> second = build(text);
  second.prepare();
  second.particles() = first.particles();
  NamedValues state;
  first.save_state(state);
  second.resume(first.clock(), state);
  for (int s = 0; s < 35; ++s) second.step();
  EXPECT_TRUE(bit_identical(straight.particles(), second.particles()));
  NamedValues a, b;
  straight.stepper().add_metrics(a);
  second.stepper().add_metrics(b);
  EXPECT_EQ(a, b);
  // The warm starts matter: zeroed, the resumed run differs.
  Simulation<double> cold = build(text);
  cold.prepare();
  cold.particles() = first.particles();
  for (const char* name : {"dfsph_kappa", "dfsph_kappa_v"}) {
    auto& k = cold.particles().extra(cold.particles().find_field(name));
    std::fill(k.begin(), k.end(), 0.0);
  }
  cold.resume(first.clock(), state);
  for (int s = 0; s < 35; ++s) cold.step();
  EXPECT_FALSE(bit_identical(straight.particles(), cold.particles()));
}

TEST(Dfsph, ASolveThatCannotConvergeStopsTheRunWithItsCause) {
  Simulation<double> sim = build(column_scene(0.15, 0.1, 0.25, 0.4, 0.025, 0.002, "dfsph",
                                              "[sph.dfsph]\nmax_iterations = 1\ndensity_tolerance = 1e-9\n"));
  sim.start();
  try {
    for (int s = 0; s < 20; ++s) sim.step();
    FAIL() << "no blow-up";
  } catch (const SimulationError& e) {
    EXPECT_EQ(e.cause(), BlowUpCause::NotConverged);
    const std::string what = e.what();
    EXPECT_NE(what.find("constant-density solver did not converge"), std::string::npos) << what;
    EXPECT_NE(what.find("after 1 iterations"), std::string::npos) << what;
    EXPECT_NE(what.find("sph.dfsph.max_iterations"), std::string::npos) << what;
  }
}

TEST(Dfsph, TheSceneRefusesWhatDfsphDoesNotRun) {
  auto refused = [](std::string_view extra, std::string_view method, std::string_view needle) {
    try {
      scene::parse_scene(column_scene(0.15, 0.1, 0.25, 0.4, 0.025, 0.002, method, extra), "scene.toml");
      ADD_FAILURE() << "accepted: " << extra;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refused("neighbour_search = \"hash\"", "dfsph", "sph.neighbour_search");
  refused("gradient_correction = true", "dfsph", "sph.gradient_correction");
  refused("kernel = \"cubic_spline\"", "wcsph", "sph.kernel");
  refused("[sph.dfsph]\nmax_iterations = 5", "wcsph", "dfsph");
  // The default kernel follows the method; old scenes keep theirs.
  EXPECT_EQ(scene::parse_scene(column_scene(0.15, 0.1, 0.25, 0.4, 0.025, 0.002, "dfsph"), "s.toml").sph->kernel,
            sph::SphKernel::CubicSpline);
  EXPECT_EQ(scene::parse_scene(column_scene(0.15, 0.1, 0.25, 0.4, 0.025, 0.002, "wcsph"), "s.toml").sph->kernel,
            sph::SphKernel::Thesis);
}

}  // namespace
