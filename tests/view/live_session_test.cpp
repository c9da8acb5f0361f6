// A live session (view/live_run.hpp) driven by WebSocket clients of our own
// (Boost.Beast): the hello and the frames a page receives, pause / step /
// resume, the mouse's push moving the fluid, the surface meshes (the fluid's
// volume, only to the viewers who ask, only while someone does), and hostile
// messages — unknown kinds, bad values, an oversized message — dropped
// without stopping the run or the other viewers.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <mutex>
#include <vector>
#include <string>
#include <thread>
#include <utility>

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>

#include "swirl/render/surface_mesh.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/view/live_run.hpp"
#include "swirl/sim/mechanics.hpp"
#include "swirl/view/push_force.hpp"
#include "view/ws_client.hpp"

namespace swirl::view {
namespace {

using namespace std::chrono_literals;
using test::Viewer;

std::uint64_t field_u64(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? 0 : std::stoull(json.substr(at + key.size() + 3));
}

class LiveSession : public ::testing::Test {
 protected:
  void start(bool paused = false, bool surface = false) {
    const std::string file = std::string(SWIRL_SOURCE_DIR) + "/examples/dam_break.toml";
    // The column fills the box's y exactly (16 layers of 0.03): symmetric across y = 0.24.
    const std::vector<std::string> overrides{"particles.0.spacing=0.03", "simulation.end_time=100",
                                             "box.max=[1.0, 0.48, 0.6]", "particles.0.max=[0.3, 0.48, 0.4]"};
    scene_ = scene::load_scene(file, overrides);
    options_.server.port = 0;
    options_.fps = 60;
    options_.threads = 1;
    options_.start_paused = paused;
    options_.surface = surface;
    options_.stop = &stop_;
    options_.log = [this](const std::string& line) {
      std::lock_guard lock(log_mutex_);
      log_.push_back(line);
    };
    std::promise<std::uint16_t> listening;
    auto port = listening.get_future();
    options_.on_listening = [&listening](const LiveServer& s) { listening.set_value(s.port()); };
    run_ = std::async(std::launch::async, [this] { return view_scene(scene_, options_); });
    port_ = port.get();
  }
  ViewResult finish() {
    stop_ = true;
    return run_.get();
  }
  void TearDown() override {
    if (run_.valid()) finish();
  }

  std::vector<std::string> log() {
    std::lock_guard lock(log_mutex_);
    return log_;
  }

  scene::Scene scene_;
  ViewOptions options_;
  std::mutex log_mutex_;
  std::vector<std::string> log_;
  std::atomic<bool> stop_{false};
  std::future<ViewResult> run_;
  std::uint16_t port_ = 0;
};

TEST_F(LiveSession, AViewerGetsTheHelloAndFramesOfTheRunningScene) {
  start();
  Viewer v(port_);
  auto [text, hello] = v.next();
  ASSERT_TRUE(text);
  EXPECT_NE(hello.find("\"type\":\"hello\""), std::string::npos) << hello;
  EXPECT_NE(hello.find("\"speed\""), std::string::npos) << hello;
  EXPECT_NE(hello.find("\"box\":[0,0,0,1,0.48,0.6]"), std::string::npos) << hello;
  const DecodedFrame a = v.frame();
  const std::uint64_t n = field_u64(hello, "particles");
  ASSERT_GT(n, 100u);
  EXPECT_EQ(a.x.size(), n);
  DecodedFrame b = v.frame();
  for (int k = 0; k < 100 && b.step <= a.step; ++k) b = v.frame();  // the run goes on: newer states arrive
  EXPECT_GT(b.step, a.step);
  const ViewResult r = finish();
  EXPECT_GT(r.steps, 0u);
  EXPECT_GE(r.server.frames_sent, 2u);
}

TEST_F(LiveSession, PauseStepAndResumeActBetweenSteps) {
  start(/*paused=*/true);
  Viewer v(port_);
  const std::uint64_t s0 = field_u64(v.status(), "step");
  EXPECT_EQ(field_u64(v.status(), "step"), s0) << "paused: no steps";
  v.send(encode_control(control::Step{}));
  std::string st = v.status();
  EXPECT_EQ(field_u64(st, "step"), s0 + 1) << st;
  EXPECT_NE(st.find("\"paused\":true"), std::string::npos) << st;
  v.send(encode_control(control::Resume{}));
  std::uint64_t s = s0 + 1;
  for (int k = 0; k < 5 && s <= s0 + 1; ++k) s = field_u64(v.status(), "step");
  EXPECT_GT(s, s0 + 1);
}

// The statuses carry the numbers of the run's diagnostics.csv, for the
// page's plots: at step 0 (paused) they equal those of the same scene built
// and started here (sim/mechanics.hpp: the fluid's kinetic energy, the SPH
// solver's mean and largest density error), to the 9 digits of the message.
TEST_F(LiveSession, StatusesCarryTheRunsDiagnostics) {
  start(/*paused=*/true);
  Viewer v(port_);
  const std::string st = v.status();
  ASSERT_EQ(field_u64(st, "step"), 0u) << st;
  ASSERT_EQ(scene_.precision, scene::Precision::Float);
  auto sim = sim::build_simulation<float>(scene_);
  sim.start();
  const auto expected = sim::diagnostic_values(sim, sim.particles(), sim.settings().block_size);
  const auto at = st.find("\"diagnostics\":{");
  ASSERT_NE(at, std::string::npos) << st;
  const std::string diagnostics = st.substr(at, st.find('}', at) - at);
  std::size_t seen = 0;
  for (const auto& [name, value] : expected) {
    if (name != "mean_density_error" && name != "max_density_error") continue;
    ++seen;
    ASSERT_NE(diagnostics.find("\"" + name + "\":"), std::string::npos) << diagnostics;
    EXPECT_NEAR(test::json_number_at(diagnostics, name), value, 1e-8 * value) << name;
    EXPECT_GT(value, 0.0) << name;  // a lattice column is not at ρ0 everywhere
  }
  EXPECT_EQ(seen, 2u);
  EXPECT_EQ(test::json_number_at(st, "kinetic_energy"), sim::mechanics(sim.particles(), sim.settings().block_size).kinetic);  // at rest: 0
  // After single steps the column falls: the kinetic energy grows.
  for (int k = 0; k < 5; ++k) v.send(encode_control(control::Step{}));
  std::string later = v.status();
  for (int k = 0; k < 20 && field_u64(later, "step") < 5; ++k) later = v.status();
  ASSERT_EQ(field_u64(later, "step"), 5u) << later;
  EXPECT_GT(test::json_number_at(later, "kinetic_energy"), 0.0) << later;
}

TEST_F(LiveSession, HostileMessagesAreDroppedAndTheRunAndOtherViewersGoOn) {
  start();
  Viewer good(port_), bad(port_);
  bad.send(std::string(1, char(99)));                          // unknown kind
  bad.send(std::string(40, char(7)));                          // wrong length
  std::string nan_push = encode_control(control::Push{{0, 0, 0}, {0, 0, 0}, 1, 1, true});
  nan_push[1] = nan_push[2] = nan_push[3] = char(0xff), nan_push[4] = char(0x7f);  // x = NaN
  bad.send(nan_push);
  bad.send("{\"type\":\"pwn\"}", /*text=*/true);  // text is no control either
  bad.send(std::string(1, char(2)));  // a valid resume after them: the session is still open
  bad.send(std::string(5000, 'x'));   // over the 1024-byte limit: this session ends
  EXPECT_TRUE(bad.closed_by_server()) << "the oversized message should close the session";
  const std::uint64_t before = good.frame().step;
  std::uint64_t after = before;
  for (int k = 0; k < 100 && after <= before; ++k) after = good.frame().step;
  EXPECT_GT(after, before) << "the other viewer still receives a running simulation";
  const ViewResult r = finish();
  EXPECT_GE(r.server.dropped, 5u);
  EXPECT_GE(r.server.controls, 1u);
}

// The push drags the particles under it with the pointer's velocity. The dam
// break is symmetric across y (the column fills the box's width, the flow
// along x and z), so without a push the particles' mean y stays put; a push along +y at
// the top of the column moves it.
float mean_y(const DecodedFrame& f) {
  double sum = 0;
  for (const float y : f.y) sum += y;
  return float(sum / double(f.y.size()));
}

// The volume a decoded mesh's triangles enclose.
double volume_of(const DecodedMesh& m) {
  render::SurfaceMesh mesh;
  mesh.vertices = m.vertices;
  mesh.indices = m.indices;
  return render::enclosed_volume(mesh);
}

// The fluid's volume Σ m/ρ0 of a scene's initial particles (its lattice mass
// makes an interior particle's SPH density ρ0).
double fluid_volume(const scene::Scene& scene) {
  const auto sim = sim::build_simulation<float>(scene);
  double v = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) v += double(sim.particles().mass[i]);
  return v / scene.sph->rest_density;
}

// The dam break's column (0.3 × 0.48 × 0.4 m of water, particles 0.03 m
// apart against the box's walls): the surface a viewer turns on encloses the
// fluid's volume Σ m/ρ0 within a few per cent at the start, and still after
// the column has fallen for 150 steps.
TEST_F(LiveSession, SurfaceMeshesEncloseTheFluidsVolume) {
  start(/*paused=*/true);
  const double fluid = fluid_volume(scene_);
  Viewer v(port_);
  auto [text, hello] = v.next();
  EXPECT_NE(hello.find(R"("surface":true,"surface_on":false)"), std::string::npos) << hello;
  v.send(encode_control(control::Surface{true}));
  const DecodedMesh a = v.mesh();
  EXPECT_EQ(a.step, 0u) << "paused: the surface of the state shown";
  EXPECT_GT(a.triangle_count(), 1000u);
  EXPECT_EQ(a.iso, 0.5f);
  EXPECT_NEAR(a.cell, 0.03f, 0.001f) << "the view's cell: one particle spacing";
  const double va = volume_of(a);
  std::printf("surface at step 0: %zu vertices, %zu triangles, %.6f m³ (fluid %.6f m³, ratio %.4f)\n",
              a.vertices.size(), a.triangle_count(), va, fluid, va / fluid);
  EXPECT_NEAR(va / fluid, 1.0, 0.04);
  // 150 single steps: each one's state is offered to the mesher (a state
  // waiting for it is replaced), so the last mesh is step 150's, whatever the
  // machine's speed; one thread: the same run every time.
  for (int k = 0; k < 150; ++k) v.send(encode_control(control::Step{}));
  DecodedMesh b = v.mesh();
  for (int k = 0; k < 400 && b.step < 150; ++k) b = v.mesh();
  ASSERT_EQ(b.step, 150u);
  const double vb = volume_of(b);
  std::printf("surface at step %llu: %zu triangles, %.6f m³ (ratio %.4f)\n", static_cast<unsigned long long>(b.step),
              b.triangle_count(), vb, vb / fluid);
  EXPECT_NEAR(vb / fluid, 1.0, 0.05);
  EXPECT_GT(std::abs(b.lo[0] - a.lo[0]) + std::abs(b.hi[0] - a.hi[0]) + std::abs(b.hi[2] - a.hi[2]), 0.01)
      << "the surface follows the falling column";
  const ViewResult r = finish();
  EXPECT_GE(r.mesher.meshes, 2u);
  EXPECT_GE(r.server.meshes_sent, 2u);
}

// Meshes go only to the viewers that turned the surface on, and are made
// only while one has: none before, none after the last one turns it off.
TEST_F(LiveSession, MeshesAreMadeForAndSentToTheViewersWhoAskOnly) {
  start();
  Viewer asks(port_), not_asking(port_);
  const auto meshes_made_in = [](const std::string& status) {  // the server's count of meshes made
    const auto at = status.find(R"("surface":{"meshes":)");
    return at == std::string::npos ? ~std::uint64_t{0} : std::stoull(status.substr(at + 20));
  };
  const auto meshes_made = [&](Viewer& v) { return meshes_made_in(test::next_text(v, "status")); };
  for (int k = 0; k < 10; ++k) not_asking.frame();
  EXPECT_EQ(meshes_made(not_asking), 0u) << "nobody asked: no mesh made";
  asks.send(encode_control(control::Surface{true}));
  const DecodedMesh first = asks.mesh();
  EXPECT_GT(first.triangle_count(), 100u);
  for (int k = 0; k < 3; ++k) EXPECT_GT(asks.mesh().step, first.step - 1);
  for (int k = 0; k < 30; ++k) {  // the other viewer's binary messages are all frames
    auto [text, data] = not_asking.next();
    EXPECT_FALSE(!text && Viewer::is_mesh(data)) << "a mesh sent to a viewer that did not ask";
  }
  asks.send(encode_control(control::Surface{false}));
  std::this_thread::sleep_for(300ms);  // a mesh in the making when it was turned off may still finish
  // A slow reader's socket holds a backlog of older statuses; the first one
  // showing a pause (or resume) it asked for is newer than that request.
  const auto status_after = [&](bool pause) {
    not_asking.send(encode_control(pause ? Control{control::Pause{}} : Control{control::Resume{}}));
    const std::string flag = pause ? R"("paused":true)" : R"("paused":false)";
    for (;;) {
      std::string st = test::next_text(not_asking, "status");
      if (st.find(flag) != std::string::npos) return st;
    }
  };
  const std::string off = status_after(true);
  const std::uint64_t after_off = meshes_made_in(off);
  status_after(false);
  std::this_thread::sleep_for(1s);  // the run goes on without a mesh
  const std::string later = status_after(true);
  EXPECT_GT(after_off, 0u);
  EXPECT_GT(field_u64(later, "step"), field_u64(off, "step")) << "steps were made after the surface went off";
  EXPECT_EQ(meshes_made_in(later), after_off) << "no viewer wants the surface: no mesh made";
}

// --surface: a viewer starts with the surface on, without asking.
TEST_F(LiveSession, WithSurfaceOnAViewerGetsMeshesWithoutAsking) {
  start(/*paused=*/true, /*surface=*/true);
  Viewer v(port_);
  auto [text, hello] = v.next();
  EXPECT_NE(hello.find(R"("surface":true,"surface_on":true)"), std::string::npos) << hello;
  EXPECT_GT(v.mesh().triangle_count(), 100u);
}

TEST_F(LiveSession, TheMousePushMovesTheFluid) {
  start(/*paused=*/true);
  Viewer v(port_);
  const DecodedFrame before = v.frame();
  float top = 0;
  for (std::size_t i = 0; i < before.z.size(); ++i) top = std::max(top, before.z[i]);
  const float y0 = mean_y(before);
  v.send(encode_control(control::Push{{0.15f, 0.24f, top}, {0, 3, 0}, 0.12f, 100, true}));
  constexpr int kSteps = 100;  // 0.04 s
  for (int k = 0; k < kSteps; ++k) v.send(encode_control(control::Step{}));
  DecodedFrame after = v.frame();
  for (int k = 0; k < 10 * kSteps && after.step < before.step + kSteps; ++k) after = v.frame();  // the last step's state
  ASSERT_EQ(after.step, before.step + kSteps);
  // Measured: +3.0 mm with the push; without it (on = false) 0.00 mm.
  EXPECT_GT(mean_y(after) - y0, 0.0005f) << "the push along +y should move the fluid's mean y";
}

float mean_z(const DecodedFrame& f) {
  double sum = 0;
  for (const float z : f.z) sum += z;
  return float(sum / double(f.z.size()));
}

// The sliders' parameters: the hello offers the dam break's viscosity and
// gravity (not the softening: no [nbody]) with the scene's values and ranges;
// a new value reaches the solver between steps (the status reads it back from
// the solver; gravity turned upward lifts the fluid instead of letting it
// fall) and is logged with its step; values outside the range, and a
// parameter the run does not have, are refused and change nothing.
TEST_F(LiveSession, ParameterChangesReachTheSimulationAndOutOfRangeOnesAreRefused) {
  start(/*paused=*/true);
  Viewer v(port_);
  auto [text, hello] = v.next();
  ASSERT_TRUE(text);
  EXPECT_NE(hello.find(R"({"id":0,"key":"sph.viscosity","label":"viscosity","unit":"Pa·s","vector":false,"min":0,"max":5,)"),
            std::string::npos) << hello;  // the dam break's 0.5 Pa·s: 10 x 0.5 at most
  EXPECT_NE(hello.find(R"("key":"forces.gravity")"), std::string::npos) << hello;
  EXPECT_EQ(hello.find("nbody.softening"), std::string::npos) << hello;
  EXPECT_DOUBLE_EQ(test::json_number_at(test::next_text(v, "status"), "sph.viscosity"), 0.5);

  using control::Parameter, control::ParameterId;
  v.send(encode_control(Parameter{ParameterId::Viscosity, {1.5f, 0, 0}}));
  std::string st = test::next_text(v, "status");
  for (int k = 0; k < 20 && test::json_number_at(st, "sph.viscosity") != 1.5; ++k) st = test::next_text(v, "status");
  EXPECT_DOUBLE_EQ(test::json_number_at(st, "sph.viscosity"), 1.5) << st;

  // Refused: below the key's range (>= 0), above the view's bound, a parameter the scene lacks.
  v.send(encode_control(Parameter{ParameterId::Viscosity, {-0.1f, 0, 0}}));
  EXPECT_NE(test::next_text(v, "refused").find("sph.viscosity = -0.1 Pa·s is outside [0, 5]"), std::string::npos);
  v.send(encode_control(Parameter{ParameterId::Viscosity, {6, 0, 0}}));
  EXPECT_NE(test::next_text(v, "refused").find("outside"), std::string::npos);
  v.send(encode_control(Parameter{ParameterId::Gravity, {0, 0, -100}}));  // |g| over 4 x 9.81
  EXPECT_NE(test::next_text(v, "refused").find("forces.gravity magnitude = 100"), std::string::npos);
  v.send(encode_control(Parameter{ParameterId::Softening, {0.01f, 0, 0}}));
  EXPECT_NE(test::next_text(v, "refused").find("no parameter 2"), std::string::npos);
  st = test::next_text(v, "status");
  EXPECT_DOUBLE_EQ(test::json_number_at(st, "sph.viscosity"), 1.5) << "a refused value changes nothing: " << st;

  // Gravity upward: 50 steps (0.02 s) lift the column's mean z, where it would fall.
  v.send(encode_control(control::Step{}));  // a frame to start from (the first was skipped over above)
  const DecodedFrame before = v.frame();
  v.send(encode_control(Parameter{ParameterId::Gravity, {0, 0, 9.81f}}));
  constexpr int kSteps = 50;
  for (int k = 0; k < kSteps; ++k) v.send(encode_control(control::Step{}));
  DecodedFrame after = v.frame();
  for (int k = 0; k < 10 * kSteps && after.step < before.step + kSteps; ++k) after = v.frame();
  ASSERT_EQ(after.step, before.step + kSteps);
  EXPECT_GT(mean_z(after) - mean_z(before), 0.0005f) << "g = +9.81 z should lift the fluid";

  const ViewResult r = finish();
  EXPECT_EQ(r.parameter_changes, 2u);
  EXPECT_EQ(r.refused, 4u);
  int logged = 0;
  for (const auto& line : log())
    if (line.find("sph.viscosity 0.5 Pa·s -> 1.5 Pa·s") != std::string::npos ||
        line.find("forces.gravity (0, 0, -9.81) m/s² -> (0, 0, 9.81) m/s²") != std::string::npos)
      ++logged;
  EXPECT_EQ(logged, 2) << "each change is logged with its step";
}

// A gravity run offers the softening (only): a larger ε reaches the tree
// walk, whose potential energy |W| then drops, where one step without the
// change leaves it as it was.
TEST(LiveSessionGravity, TheSofteningSliderReachesTheTreeWalk) {
  const scene::Scene scene = scene::load_scene(std::string(SWIRL_SOURCE_DIR) + "/examples/plummer.toml",
                                               std::vector<std::string>{"particles.0.count=400"});
  std::atomic<bool> stop{false};
  ViewOptions options;
  options.threads = 1;
  options.start_paused = true;
  options.stop = &stop;
  std::promise<std::uint16_t> listening;
  auto port = listening.get_future();
  options.on_listening = [&listening](const LiveServer& s) { listening.set_value(s.port()); };
  auto run = std::async(std::launch::async, [&] { return view_scene(scene, options); });
  {
    Viewer v(port.get());
    auto [text, hello] = v.next();
    EXPECT_NE(hello.find(R"("key":"nbody.softening")"), std::string::npos) << hello;
    EXPECT_EQ(hello.find("sph.viscosity"), std::string::npos) << hello;
    EXPECT_EQ(hello.find("forces.gravity"), std::string::npos) << "no uniform field in a Plummer sphere: " << hello;
    auto step = [&] {  // one step; its status
      const std::uint64_t s0 = field_u64(test::next_text(v, "status"), "step");
      v.send(encode_control(control::Step{}));
      std::string st = test::next_text(v, "status");
      for (int k = 0; k < 20 && field_u64(st, "step") <= s0; ++k) st = test::next_text(v, "status");
      return st;
    };
    const std::string a = step(), b = step();
    EXPECT_DOUBLE_EQ(test::json_number_at(b, "nbody.softening"), 0.01);
    v.send(encode_control(control::Parameter{control::ParameterId::Softening, {0.5f, 0, 0}}));
    const std::string c = step();
    EXPECT_DOUBLE_EQ(test::json_number_at(c, "nbody.softening"), 0.5) << c;
    const double w_a = test::json_number_at(a, "potential_energy"), w_b = test::json_number_at(b, "potential_energy"),
                 w_c = test::json_number_at(c, "potential_energy");
    EXPECT_LT(w_a, 0);
    EXPECT_LT(std::abs(w_b - w_a), 0.01 * std::abs(w_a)) << "one step alone";
    EXPECT_GT(w_c - w_b, 0.1 * std::abs(w_b)) << "ε = 0.5 makes the potential much shallower";
    v.send(encode_control(control::Parameter{control::ParameterId::Softening, {-0.01f, 0, 0}}));
    EXPECT_NE(test::next_text(v, "refused").find("nbody.softening"), std::string::npos);
  }
  stop = true;
  const ViewResult r = run.get();
  EXPECT_EQ(r.parameter_changes, 1u);
  EXPECT_EQ(r.refused, 1u);
}

// A gravity run has no surface: the hello says so, the control is refused
// with its reason, and --surface stops at once.
TEST(LiveSessionGravity, HasNoSurface) {
  const scene::Scene scene = scene::load_scene(std::string(SWIRL_SOURCE_DIR) + "/examples/plummer.toml",
                                               std::vector<std::string>{"particles.0.count=200"});
  std::atomic<bool> stop{false};
  ViewOptions options;
  options.threads = 1;
  options.start_paused = true;
  options.stop = &stop;
  std::promise<std::uint16_t> listening;
  auto port = listening.get_future();
  options.on_listening = [&listening](const LiveServer& s) { listening.set_value(s.port()); };
  auto run = std::async(std::launch::async, [&] { return view_scene(scene, options); });
  {
    Viewer v(port.get());
    auto [text, hello] = v.next();
    EXPECT_NE(hello.find(R"("surface":false)"), std::string::npos) << hello;
    v.send(encode_control(control::Surface{true}));
    EXPECT_NE(test::next_text(v, "refused").find("no [sph]"), std::string::npos);
  }
  stop = true;
  const ViewResult r = run.get();
  EXPECT_EQ(r.refused, 1u);
  EXPECT_EQ(r.mesher.meshes, 0u);
  options.surface = true;
  options.on_listening = nullptr;
  try {
    view_scene(scene, options);
    ADD_FAILURE() << "--surface on a gravity scene was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--surface"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[sph]"), std::string::npos) << e.what();
  }
}

TEST(PushForce, RelaxesVelocitiesTowardTheDragWithinItsRadiusOnly) {
  ParticleSet<double> p(3);
  for (std::size_t i = 0; i < 3; ++i) {
    p.position.set(i, Vec3<double>{double(i) * 0.6, 0, 0});
    p.mass[i] = 1;
  }
  PushForce<double> push;
  push.set(control::Push{{0, 0, 0}, {1, 0, 0}, 1.0f, 10, true});
  push.add_acceleration(p, SolverContext<double>{0, 1, nullptr, nullptr, {}, nullptr});
  EXPECT_DOUBLE_EQ(p.acceleration.x[0], 10.0);            // at the point: s·(u − v)
  EXPECT_NEAR(p.acceleration.x[1], 10.0 * 0.4, 1e-6);     // 0.6 R away: (1 − 0.6)
  EXPECT_EQ(p.acceleration.x[2], 0.0);                    // outside R
  push.set(control::Push{{0, 0, 0}, {1, 0, 0}, 1.0f, 10, false});
  push.add_acceleration(p, SolverContext<double>{0, 1, nullptr, nullptr, {}, nullptr});
  EXPECT_DOUBLE_EQ(p.acceleration.x[0], 10.0);  // off: nothing added
}

}  // namespace
}  // namespace swirl::view
