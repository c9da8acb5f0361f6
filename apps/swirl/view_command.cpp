// swirl view SCENE: runs the scene live and serves the page that shows and
// steers it (view/live_run.hpp); swirl view RUN_DIR: replays a finished run
// (a folder `swirl run` wrote) on the same page with a time slider
// (view/replay.hpp). The URL is printed; Ctrl-C ends the session.
// Listening beyond 127.0.0.1 (--host) needs a token in the URL, made here from
// the system's random device, so that only whoever was given the URL can use it.
// The page is opened in the user's browser when one is at hand (--open).
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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
  std::string open = "auto";    // open the page in a browser: auto, always, never
};

extern "C" char** environ;

// Opens `url` in the user's browser without waiting for it: $BROWSER's first
// entry (the common convention: a command, "%s" standing for the URL), else
// xdg-open (or macOS's open). "auto" opens only where a graphical session is
// at hand (DISPLAY or WAYLAND_DISPLAY; always on macOS): over SSH the URL is
// printed instead, for a browser at the other end of a forwarded port. What
// happened is returned, for the terminal (empty when nothing was tried).
std::string open_in_browser(const std::string& url, const std::string& mode) {
  const auto env = [](const char* name) { const char* v = std::getenv(name); return std::string(v ? v : ""); };
#ifdef __APPLE__
  const bool graphical = true;
  const std::string opener = "open";
#else
  const bool graphical = !env("DISPLAY").empty() || !env("WAYLAND_DISPLAY").empty();
  const std::string opener = "xdg-open";
#endif
  if (mode == "never" || (mode == "auto" && !graphical)) return {};
  std::string browser = env("BROWSER");
  browser = browser.substr(0, browser.find(':'));
  std::vector<std::string> argv;
  if (browser.empty()) argv = {opener, url};
  else if (const auto at = browser.find("%s"); at != std::string::npos)
    argv = {"/bin/sh", "-c", std::string(browser).replace(at, 2, url)};  // the URL is ours: no quoting needed
  else argv = {browser, url};
  std::vector<char*> raw;
  for (auto& a : argv) raw.push_back(a.data());
  raw.push_back(nullptr);
  // The browser's own chatter stays out of swirl's terminal.
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int failed = posix_spawnp(&pid, raw[0], &files, nullptr, raw.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (failed) return fmt::format("could not start {} ({}): open the URL above yourself", argv[0], std::strerror(failed));
  // Reaped on its own thread: xdg-open returns once the browser has the URL; a browser itself may run on.
  std::thread([pid] { int status = 0; ::waitpid(pid, &status, 0); }).detach();
  return fmt::format("opened in {}", browser.empty() ? opener : browser);
}

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
    if (const std::string opened = open_in_browser(server.url(), args.open); !opened.empty())
      fmt::print("swirl view: {}\n", opened);
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
  cmd->add_option("--open", args->open,
                  "Open the page in a browser ($BROWSER, else xdg-open): auto (where a display is at hand), always, never")
      ->check(CLI::IsMember({"auto", "always", "never"}));
  cmd->add_option("--seconds", args->seconds, "End the session after this many wall-clock seconds (0: at Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  commands.push_back({cmd, [args] { return view(*args); }});
}

}  // namespace swirl::cli
