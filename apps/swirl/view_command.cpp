// swirl view SCENE: runs the scene live and serves the page that shows and
// steers it (view/live_run.hpp); swirl view RUN_DIR: replays a finished run
// (a folder `swirl run` wrote) on the same page with a time slider
// (view/replay.hpp). The URL is printed; Ctrl-C ends the session.
// Listening beyond 127.0.0.1 (--host) needs a token in the URL, made here from
// the system's random device, so that only whoever was given the URL can use it.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "cli.hpp"
#include "commands.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/view/live_run.hpp"
#include "swirl/view/replay.hpp"

namespace swirl::cli {
namespace {

std::atomic<bool> g_view_stop{false};
extern "C" void on_view_signal(int) { g_view_stop.store(true); }

struct ViewArgs {
  std::string scene;
  std::vector<std::string> overrides;
  std::string host = "127.0.0.1";
  unsigned port = 8765;
  int threads = 0;
  double fps = 30;
  bool paused = false;
  bool surface = false;      // viewers start with the fluid's surface on
  double surface_cell = 1.0;  // the view's surface grid cell, particle spacings
  double seconds = 0;  // stop after this many wall seconds (0: run until Ctrl-C)
  std::string format = "auto";  // replay: the frames to read (auto, vtp, h5)
};

std::string random_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) token += fmt::format("{:08x}", device());
  return token;
}

int view(const ViewArgs& args) {
  std::error_code ec;
  const bool replay = std::filesystem::is_directory(args.scene, ec);
  std::optional<scene::Scene> scene;
  std::optional<view::RunFrames> run;
  if (replay) {
    if (!args.overrides.empty())
      throw std::invalid_argument(fmt::format("swirl view: --set changes a scene; {} is a run folder (replayed as it is)", args.scene));
    const view::ReplayFormat format = args.format == "vtp" ? view::ReplayFormat::Vtp
                                      : args.format == "h5" ? view::ReplayFormat::Hdf5
                                                            : view::ReplayFormat::Auto;
    run = view::open_run(args.scene, format);
    if (!run->scene_note.empty())
      fmt::print(stderr, "swirl view: {}/scene.toml does not read ({}); positions are shown in each frame's bounds\n",
                 args.scene, run->scene_note);
  } else {
    if (args.format != "auto") throw std::invalid_argument("swirl view: --format chooses a run folder's frames; a scene has none");
    scene = load_scene_file(args.scene, args.overrides);
  }
  view::ViewOptions options;
  options.server.host = args.host;
  options.server.port = static_cast<std::uint16_t>(args.port);
  if (args.host != "127.0.0.1" && args.host != "::1") options.server.token = random_token();
  options.threads = args.threads;
  options.fps = args.fps;
  options.start_paused = args.paused;
  options.surface = args.surface;
  options.surface_cell = args.surface_cell;
  options.stop = &g_view_stop;
  options.log = [](const std::string& line) { fmt::print(stderr, "{}\n", line); };
  options.on_listening = [&](const view::LiveServer& server) {
    if (replay)
      fmt::print("swirl view: replaying {} ({} frames) at {}\n(Ctrl-C ends the session)\n", args.scene, run->frames.size(),
                 server.url());
    else
      fmt::print("swirl view: {} live at {}\n(Ctrl-C ends the session)\n", args.scene, server.url());
    std::fflush(stdout);
  };
  g_view_stop.store(false);
  std::signal(SIGINT, on_view_signal);
  std::signal(SIGTERM, on_view_signal);
  std::unique_ptr<std::thread> timer;
  if (args.seconds > 0)
    timer = std::make_unique<std::thread>([s = args.seconds] {
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
      while (!g_view_stop.load() && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      g_view_stop.store(true);
    });
  // The timer ends with the session, also when the session throws (a first frame that does not read).
  struct JoinTimer {
    std::unique_ptr<std::thread>& timer;
    ~JoinTimer() {
      g_view_stop.store(true);
      if (timer) timer->join();
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
    }
  };
  view::ViewResult r;
  {
    JoinTimer join{timer};
    r = replay ? view::replay_run(*run, options) : view::view_scene(*scene, options);
  }
  // The surface meshes, when a viewer asked for them (tools/view_overhead.mjs reads this line too).
  const std::string meshes =
      r.mesher.meshes + r.mesher.failed == 0
          ? std::string()
          : fmt::format("; {} surface meshes ({:.1f} ms a mesh, at most {:.1f}; {} vertices and {} triangles the last), "
                        "{} sent ({:.1f} MB){}",
                        r.mesher.meshes, r.mesher.meshes ? 1e3 * r.mesher.seconds / double(r.mesher.meshes) : 0.0,
                        1e3 * r.mesher.max_seconds, r.mesher.vertices, r.mesher.triangles, r.server.meshes_sent,
                        double(r.server.mesh_bytes_sent) / 1e6,
                        r.mesher.failed ? fmt::format(", {} not made", r.mesher.failed) : std::string());
  if (replay) {
    fmt::print("swirl view: {} frames shown in {:.1f} s; {} frames read, {:.1f} ms a frame; {} frames sent ({:.1f} MB), "
               "{} controls, {} dropped, {} refused, {} viewers{}\n",
               r.steps, r.wall_seconds, r.frames_read, r.frames_read ? 1e3 * r.read_seconds / double(r.frames_read) : 0.0,
               r.server.frames_sent, double(r.server.bytes_sent) / 1e6, r.server.controls, r.server.dropped, r.refused,
               r.server.sessions, meshes);
    return 0;
  }
  // steps/s over the session after the set-up (tools/view_overhead.mjs reads this line).
  const double stepping = r.wall_seconds - r.setup_seconds;
  fmt::print("swirl view: {} steps in {:.1f} s ({} resets; {:.2f} steps/s after {:.1f} s of set-up); {} frames sent ({:.1f} MB), "
             "{} controls, {} dropped, {} viewers; {} parameter changes, {} refused{}\n",
             r.steps, r.wall_seconds, r.resets, stepping > 0 ? double(r.steps) / stepping : 0.0, r.setup_seconds,
             r.server.frames_sent, double(r.server.bytes_sent) / 1e6, r.server.controls, r.server.dropped, r.server.sessions,
             r.parameter_changes, r.refused, meshes);
  return 0;
}

}  // namespace

void add_view_command(CLI::App& app, Commands& commands) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand("view", "Run a scene live and watch and steer it in the browser, or replay a run folder");
  cmd->add_option("scene", args->scene, "Scene file (TOML), or a run folder written by swirl run (replayed)")->required();
  cmd->add_option("--set", args->overrides, "Override a scene key: KEY=VALUE (TOML value)");
  cmd->add_option("--host", args->host, "Address to listen on (beyond 127.0.0.1 a random token guards the URL)");
  cmd->add_option("--port", args->port, "Port (0: any free one)")->check(CLI::Range(0u, 65535u));
  cmd->add_option("--threads", args->threads, "Worker threads of the simulation (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--fps", args->fps, "Frames per second sent at most")->check(CLI::Range(0.1, 240.0));
  cmd->add_flag("--paused", args->paused, "Start paused");
  cmd->add_flag("--surface", args->surface,
                "Viewers start with the fluid drawn as its surface (SPH scenes and runs; the page's \"surface\" box)");
  cmd->add_option("--surface-cell", args->surface_cell,
                  "The surface mesh's grid cell in particle spacings (finer: smoother, slower to make and send)")
      ->check(CLI::Range(0.05, 4.0));
  cmd->add_option("--format", args->format, "Replay: the frames to read, vtp (particles.pvd) or h5 (snapshots); auto: vtp when present")
      ->check(CLI::IsMember({"auto", "vtp", "h5"}));
  cmd->add_option("--seconds", args->seconds, "End the session after this many wall-clock seconds (0: at Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  commands.push_back({cmd, [args] { return view(*args); }});
}

}  // namespace swirl::cli
