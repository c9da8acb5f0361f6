// Moving obstacles (an obstacle's `motion`: boundary/rigid_motion.hpp,
// boundary/moving_boundaries.hpp): their particles at the closed-form pose
// after every step, ψ right where they are, the order's skin seeing them move,
// no fluid particle through a moving piston, the piston's wave reaching the far
// wall, bit-identity across thread counts and a resume, and the scene's
// refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "swirl/core/particle_kind.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sph/kernels.hpp"
#include "swirl/sph/probes.hpp"

namespace {

using namespace swirl;
constexpr double kPi = std::numbers::pi;

// A tank [0, L] × [0, D] × [0, H] with particle walls, water [x0, L] × [0, D]
// × [0, depth] at spacing s, adaptive steps up to dt, and `more` at the end
// (the obstacles).
std::string flume(double L, double D, double H, double x0, double depth, double s, double dt, std::string_view method,
                  std::string_view more, std::string_view extra = "") {
  return fmt::format(R"(
[simulation]
precision = "double"
dt = "adaptive"
dt_max = {dt}
end_time = 10
block_size = 64

[box]
min = [0.0, 0.0, 0.0]
max = [{L}, {D}, {H}]
walls = "particles"

[forces]
gravity = [0.0, 0.0, -9.81]

[sph]
neighbours = 30
rest_density = 1000.0
sound_speed = 20.0
viscosity = 0.05
negative_pressure = "zero"
method = "{method}"
{extra}

[[particles]]
kind = "fluid_block"
min = [{x0}, 0.0, 0.0]
max = [{L}, {D}, {depth}]
spacing = {s}
{more}
)",
                     fmt::arg("dt", dt), fmt::arg("L", L), fmt::arg("D", D), fmt::arg("H", H), fmt::arg("x0", x0),
                     fmt::arg("depth", depth), fmt::arg("s", s), fmt::arg("method", method), fmt::arg("more", more),
                     fmt::arg("extra", extra));
}

// A piston plate across the tank at x = at (two sheets, one spacing apart,
// for the thesis's solver: a single sheet's push vanishes in its plane).
std::string piston(double at, double D, double H, double s, bool thick, double amplitude, double frequency,
                   double ramp, std::string_view name = "paddle") {
  return fmt::format(R"(
[[particles]]
kind = "obstacle_box"
min = [{lo}, 0.0, 0.0]
max = [{at}, {D}, {H}]
name = "{name}"
motion = {{ kind = "piston", direction = [1, 0, 0], amplitude = {A}, frequency = {f}, ramp = {T} }}
)",
                     fmt::arg("lo", thick ? at - s : at), fmt::arg("at", at), fmt::arg("D", D), fmt::arg("H", H),
                     fmt::arg("name", name), fmt::arg("A", amplitude), fmt::arg("f", frequency), fmt::arg("T", ramp));
}

Simulation<double> build(const std::string& text) { return sim::build_simulation<double>(scene::parse_scene(text, "scene.toml")); }

const std::int32_t* kinds(const ParticleSet<double>& p) {
  const std::size_t k = p.find_int_field(kKindField);
  return k == ParticleSet<double>::npos ? nullptr : p.int_field(k).data();
}

bool bit_identical(const ParticleSet<double>& a, const ParticleSet<double>& b) {
  if (a.size() != b.size() || a.id != b.id) return false;
  const auto fa = a.fields(), fb = b.fields();
  if (fa.size() != fb.size()) return false;
  for (std::size_t f = 0; f < fa.size(); ++f)
    for (int c = 0; c < fa[f].components; ++c)
      if (std::memcmp(fa[f].data[c], fb[f].data[c], a.size() * sizeof(double)) != 0) return false;
  const auto ia = a.int_fields(), ib = b.int_fields();
  if (ia.size() != ib.size()) return false;
  for (std::size_t f = 0; f < ia.size(); ++f)
    if (std::memcmp(ia[f].data[0], ib[f].data[0], a.size() * sizeof(std::int32_t)) != 0) return false;
  return true;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// ---- Where the moving particles are -------------------------------------------------

// A small tank with a piston, a flap and a rotating paddle (no fluid near
// them needed: the test is the kinematics through the whole pipeline).
std::string three_motions(std::string_view method) {
  return flume(0.8, 0.1, 0.4, 0.6, 0.1, 0.025, 0.004, method, R"(
[[particles]]
kind = "obstacle_box"
min = [0.1, 0.0, 0.05]
max = [0.1, 0.1, 0.3]
motion = { kind = "piston", direction = [1, 0, 0], amplitude = 0.04, frequency = 2.0, phase_deg = 20 }

[[particles]]
kind = "obstacle_box"
min = [0.3, 0.0, 0.0]
max = [0.3, 0.1, 0.2]
motion = { kind = "flap", axis = [0, 1, 0], point = [0.3, 0.0, 0.0], amplitude_deg = 15, frequency = 1.5, ramp = 0.1 }

[[particles]]
kind = "obstacle_box"
min = [0.42, 0.0, 0.25]
max = [0.58, 0.1, 0.25]
motion = { kind = "rotation", axis = [0, 1, 0], point = [0.5, 0.05, 0.25], angular_velocity = 6.0, start = 0.05 }
)");
}

// Closed forms written out here (independent of RigidMotion's code).
Vec3d expected_position(int k, const Vec3d& x0, double t) {
  if (k == 0) return x0 + Vec3d{0.04 * std::sin(4 * kPi * t + 20 * kPi / 180), 0, 0};
  if (k == 1) {
    const double r = t < 0.1 ? 0.5 * (1 - std::cos(kPi * t / 0.1)) : 1.0;
    const double theta = 15 * kPi / 180 * r * std::sin(3 * kPi * t);
    const double dx = x0.x - 0.3, dz = x0.z;  // about +y through (0.3, ·, 0)
    return {0.3 + dx * std::cos(theta) + dz * std::sin(theta), x0.y, -dx * std::sin(theta) + dz * std::cos(theta)};
  }
  const double theta = 6.0 * std::max(t - 0.05, 0.0);
  const double dx = x0.x - 0.5, dz = x0.z - 0.25;
  return {0.5 + dx * std::cos(theta) + dz * std::sin(theta), x0.y, 0.25 - dx * std::sin(theta) + dz * std::cos(theta)};
}

TEST(MovingObstacles, TheirParticlesAreAtTheClosedFormPoseAfterEveryStep) {
  for (const char* method : {"dfsph", "wcsph"}) {
    const auto t0 = std::chrono::steady_clock::now();
    const scene::Scene s = scene::parse_scene(three_motions(method), "scene.toml");
    const auto ids = scene::obstacle_ids(s);
    std::vector<std::vector<Vec3d>> rest;
    for (const auto& source : s.sources)
      if (const auto* o = std::get_if<scene::ObstacleSource>(&source)) rest.push_back(scene::obstacle_points(*o));
    ASSERT_EQ(rest.size(), 3u);
    Simulation<double> sim = sim::build_simulation<double>(s);
    sim.start();
    double worst = 0, worst_speed = 0;
    std::size_t checked = 0;
    for (int step = 0; sim.time() < 0.3; ++step) {
      if (step > 0) sim.step();
      const ParticleSet<double>& p = sim.particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        for (int k = 0; k < 3; ++k) {
          const std::uint64_t id = p.id[i];
          if (id < ids[k].first || id >= ids[k].first + ids[k].count) continue;
          const Vec3d& x0 = rest[k][id - ids[k].first];
          worst = std::max(worst, norm(p.position.get(i) - expected_position(k, x0, sim.time())));
          // v against the central difference of the closed form.
          const double d = 1e-6;
          const Vec3d v = (expected_position(k, x0, sim.time() + d) - expected_position(k, x0, sim.time() - d)) * (0.5 / d);
          // (Not across the flap's ramp end at t = 0.1, where the difference sees the jump of θ''.)
          if (sim.time() > 0.06 && std::abs(sim.time() - 0.1) > 1e-4) worst_speed = std::max(worst_speed, norm(p.velocity.get(i) - v));
          ++checked;
        }
    }
    EXPECT_LT(worst, 1e-14) << method;  // rounding of the rotation's few operations
    EXPECT_LT(worst_speed, 1e-7) << method;
    EXPECT_GT(checked, 1000u);
    std::printf("%s: %zu checks, worst |x − x(t)| = %.3g m, |v − v(t)| = %.3g m/s (%.2f s)\n", method, checked, worst,
                worst_speed, seconds_since(t0));
  }
}

// ψ_b stays Akinci's ρ0/Σ_k W_bk over the boundary neighbours where the
// obstacles are now (recomputed every evaluation): the rotating paddle passes
// the flap's top and the piston stays clear of the walls' corner.
TEST(MovingObstacles, PsiIsTheBruteForceSumWhereTheObstaclesAreNow) {
  for (const char* method : {"dfsph", "wcsph"}) {
    Simulation<double> sim = build(three_motions(method));
    sim.start();
    while (sim.time() < 0.2) sim.step();
    const ParticleSet<double>& p = sim.particles();
    const auto& fluid = *sim.find_solver<sph::SphFluid<double>>();
    const double h = fluid.parameters().smoothing_length;
    const bool cubic = std::string(method) == "dfsph";
    const sph::CubicSpline<double> spline(h);
    const sph::Poly6<double> poly6(h);
    const std::int32_t* kind = kinds(p);
    double worst = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!is_boundary(kind[i])) continue;
      double sum = 0;
      for (std::size_t j = 0; j < p.size(); ++j) {
        const double r = norm(p.position.get(i) - p.position.get(j));
        if (r < h && is_boundary(kind[j])) sum += cubic ? spline(r) : poly6(r * r);
      }
      worst = std::max(worst, std::abs(p.mass[i] - 1000 / sum) / p.mass[i]);
    }
    EXPECT_LT(worst, 1e-10) << method;
  }
}

// With a Verlet skin the order is kept while no particle moved more than
// skin/2 from where it was sorted: the moving particles count too.
TEST(MovingObstacles, TheOrdersSkinSeesThemMove) {
  Simulation<double> sim = build(flume(0.8, 0.1, 0.4, 0.6, 0.1, 0.025, 0.004, "dfsph", R"(
[[particles]]
kind = "obstacle_box"
min = [0.42, 0.0, 0.25]
max = [0.58, 0.1, 0.25]
motion = { kind = "rotation", axis = [0, 1, 0], point = [0.5, 0.05, 0.25], angular_velocity = 6.0 }
)", "[sph.grid]\nskin = 0.01"));
  sim.start();
  const std::uint64_t first_epoch = sim.epoch();
  for (int step = 0; step < 40; ++step) {
    sim.step();
    const ParticleSet<double>& p = sim.particles();
    const std::size_t f = p.find_field(spatial::ParticleOrder<double>::kReferenceField);
    ASSERT_NE(f, ParticleSet<double>::npos);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec3d r{p.extra(f, 0)[i], p.extra(f, 1)[i], p.extra(f, 2)[i]};
      ASSERT_LE(norm(p.position.get(i) - r), 0.005 * (1 + 1e-12)) << "particle id " << p.id[i] << " step " << step;
    }
  }
  // The paddle's tip moves 0.08·6 = 0.48 m/s, 2 mm per 4 ms step: the order had to be renewed.
  EXPECT_GT(sim.epoch(), first_epoch + 5);
}

// ---- The fluid and a moving piston -----------------------------------------------

// A tank 0.6 m long with water 0.15 m deep, a piston at x = 0.05 swinging
// ±0.03 m at 1.2 Hz (eased in over 0.2 s). Returns the run's far-wall water
// heights; checks after every step that no fluid particle is behind the
// piston's front face.
std::vector<double> piston_run(std::string_view method, double amplitude, double end, double* closest = nullptr) {
  const bool dfsph = method == "dfsph";
  const double s = 0.025, at = 0.06, L = 0.5, D = 0.075, H = 0.3, f = 1.2, ramp = 0.2;
  // The water starts where a wall's first layer has the rest density (d − s/2 = 0.59 s for DFSPH's spline, 0.63 s for poly6).
  const std::string text = flume(L, D, H, at + (dfsph ? 0.59 : 0.63) * s, 0.15, s, dfsph ? 0.004 : 5e-4, method,
                                 piston(at, D, H, s, !dfsph, amplitude, f, ramp));
  Simulation<double> sim = build(text);
  const sph::ProbeSampler sampler(*scene::parse_scene(text, "scene.toml").sph);
  const Vec3d gauge_lo{L - 0.03, D / 2, 0}, gauge_hi{L - 0.03, D / 2, H};
  boundary::RigidMotion motion;
  motion.kind = boundary::RigidMotion::Kind::Piston;
  motion.direction = {1, 0, 0}, motion.amplitude = amplitude, motion.frequency = f, motion.ramp = ramp;
  sim.start();
  std::vector<double> heights{sampler.height(sim.particles(), gauge_lo, gauge_hi)};
  double nearest = 1;
  while (sim.time() < end) {
    sim.step();
    const ParticleSet<double>& p = sim.particles();
    const double front = at + motion.pose(sim.time()).shift.x, back = dfsph ? front : front - s;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (is_boundary(kinds(p)[i])) continue;
      nearest = std::min(nearest, p.position.x[i] - front);
      if (!(p.position.x[i] > back)) {
        ADD_FAILURE() << method << ": particle id " << p.id[i] << " at x = " << p.position.x[i]
                      << " crossed the piston, whose back is at " << back << " (t = " << sim.time() << ")";
        return heights;
      }
    }
    heights.push_back(sampler.height(p, gauge_lo, gauge_hi));
  }
  if (closest) *closest = nearest;
  return heights;
}

TEST(MovingObstacles, NoFluidParticleCrossesAMovingPiston) {
  for (const char* method : {"dfsph", "wcsph"}) {
    const auto t0 = std::chrono::steady_clock::now();
    double closest = 0;
    piston_run(method, 0.03, std::string(method) == "dfsph" ? 1.2 : 0.6, &closest);
    std::printf("%s: the fluid came within %.4f m of the piston's face (%.2f s)\n", method, closest, seconds_since(t0));
    EXPECT_LT(closest, 0.02) << method;  // it pressed against the piston (the test could fail)
  }
}

// The piston makes a wave at the far wall. The same tank with a still piston
// is the control (the block's own settling sloshes it by ±2 cm): against it,
// the gauge 3 cm from the far wall reads a crest at least 2 cm higher and a
// trough at least 1 cm lower within 1.2 s. For scale, the stroke's ±3 cm
// pushes 0.15·0.03/0.44 ≈ 1 cm of level into the tank, and a wave running up a
// wall about doubles its height.
TEST(MovingObstacles, APistonMakesAWaveThatRisesAtTheFarWall) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<double> moving = piston_run("dfsph", 0.03, 1.2);
  const std::vector<double> still = piston_run("dfsph", 1e-9, 1.2);
  ASSERT_EQ(moving.size(), still.size());  // the same adaptive steps (dt_max holds throughout)
  double crest = 0, trough = 0;
  for (std::size_t k = 0; k < moving.size(); ++k)
    crest = std::max(crest, moving[k] - still[k]), trough = std::min(trough, moving[k] - still[k]);
  std::printf("far-wall gauge: starts at %.4f m; against the still piston a crest of %+.4f m and a trough of %+.4f m "
              "(%.2f s)\n",
              moving.front(), crest, trough, seconds_since(t0));
  EXPECT_NEAR(moving.front(), 0.15, 0.02);
  EXPECT_GT(crest, 0.02);
  EXPECT_LT(trough, -0.01);
}

// ---- Determinism ------------------------------------------------------------------

// A rotating paddle under water and a flap at the tank's end.
std::string paddling_scene(std::string_view method) {
  return flume(0.5, 0.1, 0.3, 0.15, 0.12, 0.025, method == "dfsph" ? 0.004 : 5e-4, method, R"(
[[particles]]
kind = "obstacle_box"
min = [0.3, 0.0, 0.07]
max = [0.4, 0.1, 0.07]
motion = { kind = "rotation", axis = [0, 1, 0], point = [0.35, 0.05, 0.07], angular_velocity = 4.0, ramp = 0.02 }

[[particles]]
kind = "obstacle_box"
min = [0.05, 0.0, 0.0]
max = [0.05, 0.1, 0.25]
motion = { kind = "flap", axis = [0, 1, 0], point = [0.05, 0.0, 0.0], amplitude_deg = 8, frequency = 2 }
)");
}

Simulation<double> paddling(std::string_view method, int threads, int steps) {
  const int before = parallel::thread_count();
  parallel::set_thread_count(threads);
  Simulation<double> sim = build(paddling_scene(method));
  sim.start();
  for (int s = 0; s < steps; ++s) sim.step();
  parallel::set_thread_count(before);
  return sim;
}

TEST(MovingObstacles, OneAndTwoThreadsGiveTheSameBits) {
  for (const char* method : {"dfsph", "wcsph"}) {
    const auto t0 = std::chrono::steady_clock::now();
    const Simulation<double> one = paddling(method, 1, 50);
    const Simulation<double> two = paddling(method, 2, 50);
    EXPECT_TRUE(bit_identical(one.particles(), two.particles())) << method;
    std::printf("%s: 2 × 50 steps to t = %.3f s (%.2f s)\n", method, one.time(), seconds_since(t0));
  }
}

// A resume from the state a checkpoint holds (every particle field and the
// solvers' and stepper's state) goes on bit for bit: the motion is a function
// of t, and the rest positions come from the scene again.
TEST(MovingObstacles, ResumingMidRunIsBitIdentical) {
  for (const char* method : {"dfsph", "wcsph"}) {
    const Simulation<double> straight = paddling(method, 2, 50);
    const Simulation<double> first = paddling(method, 2, 20);
    const int before = parallel::thread_count();
    parallel::set_thread_count(2);
    Simulation<double> second = build(paddling_scene(method));
    second.prepare();
    second.particles() = first.particles();
    NamedValues state;
    first.save_state(state);
    second.resume(first.clock(), state);
    for (int s = 0; s < 30; ++s) second.step();
    parallel::set_thread_count(before);
    EXPECT_TRUE(bit_identical(straight.particles(), second.particles())) << method;
  }
}

// ---- The scene ----------------------------------------------------------------------

TEST(MovingObstacles, BadMotionsAreRefusedNamingTheKey) {
  const auto refused = [](const std::string& text, std::string_view needle) {
    try {
      scene::parse_scene(text, "scene.toml");
      ADD_FAILURE() << "accepted: " << needle;
    } catch (const scene::SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const auto with = [](std::string_view motion) {
    return flume(0.8, 0.1, 0.4, 0.6, 0.1, 0.025, 0.004, "dfsph",
                 fmt::format("[[particles]]\nkind = \"obstacle_box\"\nmin = [0.3, 0.0, 0.0]\nmax = [0.3, 0.1, 0.2]\n"
                             "motion = {}\n",
                             motion));
  };
  EXPECT_NO_THROW(scene::parse_scene(with("{ kind = \"piston\", direction = [1, 0, 0], amplitude = 0.1, frequency = 1 }"),
                                     "scene.toml"));
  refused(with("{ direction = [1, 0, 0] }"), "scene.toml: particles[1].motion.kind: missing required key");
  refused(with("{ kind = \"wobble\" }"), "particles[1].motion.kind: unknown motion 'wobble' (allowed: 'piston', 'flap', "
                                         "'rotation')");
  refused(with("\"piston\""), "particles[1].motion: expected a table, got a string");
  refused(with("{ kind = \"piston\", amplitude = 0.1, frequency = 1 }"),
          "particles[1].motion.direction: missing required key");
  refused(with("{ kind = \"piston\", direction = [0, 0, 0], amplitude = 0.1, frequency = 1 }"),
          "particles[1].motion.direction: must not be zero");
  refused(with("{ kind = \"piston\", direction = [1, 0, 0], amplitude = 0.1, frequency = 0 }"),
          "particles[1].motion.frequency: must be > 0, got 0");
  refused(with("{ kind = \"piston\", direction = [1, 0, 0], amplitude = 0.1, frequency = 1, axis = [0, 1, 0] }"),
          "particles[1].motion.axis: unknown key for a 'piston' motion");
  refused(with("{ kind = \"flap\", axis = [0, 1, 0], point = [0.3, 0, 0], amplitude = 10, frequency = 1 }"),
          "particles[1].motion.amplitude: unknown key for a 'flap' motion (did you mean 'amplitude_deg'?)");
  refused(with("{ kind = \"flap\", axis = [0, 0, 0], point = [0.3, 0, 0], amplitude_deg = 10, frequency = 1 }"),
          "particles[1].motion.axis: must not be zero");
  refused(with("{ kind = \"rotation\", axis = [0, 1, 0], point = [0.3, 0, 0.1], angular_velocity = 0 }"),
          "particles[1].motion.angular_velocity: must not be 0");
  refused(with("{ kind = \"piston\", direction = [1, 0, 0], amplitude = 0.1, frequency = 1, ramp = -1 }"),
          "particles[1].motion.ramp: must be >= 0, got -1");
  refused(with("{ kind = \"piston\", direction = [1, 0, 0], amplitude = 0.5, frequency = 1 }"),
          "particles[1].motion.amplitude: the 'piston' motion takes the obstacle outside the box");
  // A flap hinged at its foot may swing: its arc stays above the floor. Turned all the way round it would not.
  EXPECT_NO_THROW(scene::parse_scene(
      with("{ kind = \"flap\", axis = [0, 1, 0], point = [0.3, 0, 0], amplitude_deg = 30, frequency = 1 }"), "s.toml"));
  refused(with("{ kind = \"rotation\", axis = [0, 1, 0], point = [0.3, 0, 0], angular_velocity = 1 }"),
          "particles[1].motion.point: the 'rotation' motion takes the obstacle outside the box");
}

}  // namespace
