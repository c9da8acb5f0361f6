// The view's mesher thread (view/mesher.hpp): the message it publishes for a
// state is the one the pool would make on any thread count (its loops run
// serially on its own thread, the mesh is the same), boundary particles
// (volume 0) are left out, and a state whose mesh cannot be made is skipped
// and logged.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "swirl/parallel/for_blocks.hpp"
#include "swirl/view/mesher.hpp"

namespace swirl::view {
namespace {

using namespace std::chrono_literals;

// What a Mesher publishes and logs, with a wait for the next message.
struct Sink {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<std::shared_ptr<const std::string>> messages;
  std::vector<std::string> log;
  std::shared_ptr<const std::string> wait_for(std::size_t k) {
    std::unique_lock lock(mutex);
    if (!cv.wait_for(lock, 30s, [&] { return messages.size() > k; })) return nullptr;
    return messages[k];
  }
};

Mesher make_mesher(Sink& sink, double cell = 1.0) {
  render::FluidSurface settings;
  settings.cell = cell;
  return Mesher(
      settings,
      [&sink](std::shared_ptr<const std::string> m) {
        std::lock_guard lock(sink.mutex);
        sink.messages.push_back(std::move(m));
        sink.cv.notify_all();
      },
      [&sink](const std::string& line) {
        std::lock_guard lock(sink.mutex);
        sink.log.push_back(line);
      });
}

// A drop of water (a lattice ball, 1 cm spacing) and, with volume 0, a floor
// of boundary particles under it.
MeshInput drop(std::uint64_t step) {
  auto f = std::make_shared<FrameData>();
  f->step = step;
  f->time = 0.01 * double(step);
  MeshInput in;
  for (int k = -6; k <= 6; ++k)
    for (int j = -6; j <= 6; ++j)
      for (int i = -6; i <= 6; ++i) {
        if (i * i + j * j + k * k > 36) continue;
        f->x.push_back(0.01f * float(i)), f->y.push_back(0.01f * float(j)), f->z.push_back(0.1f + 0.01f * float(k));
        in.volumes.push_back(1e-6);
      }
  for (int j = -10; j <= 10; ++j)
    for (int i = -10; i <= 10; ++i) {
      f->x.push_back(0.01f * float(i)), f->y.push_back(0.01f * float(j)), f->z.push_back(0.0f);
      in.volumes.push_back(0.0);
    }
  in.frame = f;
  return in;
}

TEST(Mesher, PublishesTheMeshThePoolMakesOnAnyThreadCount) {
  Sink sink;
  {
    Mesher mesher = make_mesher(sink);
    mesher.offer(drop(7));
    const auto message = sink.wait_for(0);
    ASSERT_TRUE(message) << "no mesh within 30 s";
    render::FluidSurface settings;
    settings.cell = 1.0;
    for (const int threads : {1, 2, 3}) {
      parallel::set_thread_count(threads);
      const render::SurfaceMesh mesh = Mesher::mesh_of(drop(7), settings);
      EXPECT_EQ(encode_mesh(mesh, 7, 0.07), *message) << threads << " threads";
    }
    const DecodedMesh d = decode_mesh({reinterpret_cast<const std::uint8_t*>(message->data()), message->size()});
    EXPECT_EQ(d.step, 7u);
    EXPECT_GT(d.lo[2], 0.03f) << "the floor (volume 0) is left out";
    EXPECT_GT(d.triangle_count(), 500u);
  }
  EXPECT_EQ(sink.messages.size(), 1u);
}

TEST(Mesher, AStateWithoutAMeshIsSkippedAndLogged) {
  Sink sink;
  Mesher mesher = make_mesher(sink);
  MeshInput bad = drop(3);
  auto broken = std::make_shared<FrameData>(*bad.frame);
  broken->x[5] = NAN;
  bad.frame = broken;
  mesher.offer(std::move(bad));
  for (int k = 0; k < 3000 && mesher.busy(); ++k) std::this_thread::sleep_for(10ms);
  ASSERT_FALSE(mesher.busy());
  EXPECT_EQ(mesher.stats().failed, 1u);
  EXPECT_EQ(mesher.stats().meshes, 0u);
  {
    std::lock_guard lock(sink.mutex);
    EXPECT_TRUE(sink.messages.empty());
    ASSERT_EQ(sink.log.size(), 1u);
    EXPECT_NE(sink.log[0].find("the surface of step 3 was not made"), std::string::npos) << sink.log[0];
    EXPECT_NE(sink.log[0].find("not finite"), std::string::npos) << sink.log[0];
  }
  mesher.offer(drop(4));  // the next state is meshed as usual
  const auto message = sink.wait_for(0);
  ASSERT_TRUE(message);
  EXPECT_EQ(mesher.stats().meshes, 1u);
}

TEST(Mesher, RefusesBadSettingsAndMismatchedVolumes) {
  Sink sink;
  EXPECT_THROW(make_mesher(sink, 0.0), std::invalid_argument);
  EXPECT_THROW(make_mesher(sink, NAN), std::invalid_argument);
  Mesher mesher = make_mesher(sink);
  MeshInput in = drop(1);
  in.volumes.pop_back();
  EXPECT_THROW(mesher.offer(std::move(in)), std::invalid_argument);
  EXPECT_THROW(mesher.offer(MeshInput{}), std::invalid_argument);
}

}  // namespace
}  // namespace swirl::view
