#include "swirl/render/movie.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"

extern char** environ;

namespace swirl::render {
namespace fs = std::filesystem;

std::optional<fs::path> find_program(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0 && fs::is_regular_file(candidate)) return candidate;
  }
  return std::nullopt;
}

std::string ffmpeg_missing_hint() {
  return "ffmpeg is not installed (it is optional); on Debian: sudo apt-get install ffmpeg";
}

void make_movie(const std::vector<fs::path>& pngs, const fs::path& movie, int fps) {
  const auto ffmpeg = find_program("ffmpeg");
  if (!ffmpeg) throw io::IoError(movie.string() + ": cannot make the movie: " + ffmpeg_missing_hint());
  if (pngs.empty()) throw io::IoError(movie.string() + ": no frames to put in the movie");
  if (fps < 1) throw std::invalid_argument("movie: frames per second must be at least 1");

  // ffmpeg reads a numbered sequence: link the frames in order into a scratch
  // folder beside the movie, and let ffmpeg write a temporary movie there.
  const fs::path scratch = movie.parent_path() / (".movie_frames_" + std::to_string(::getpid()));
  const fs::path partial = scratch / ("partial" + movie.extension().string());
  const fs::path log = scratch / "ffmpeg.log";
  struct Cleanup {
    fs::path dir;
    ~Cleanup() { std::error_code ec; fs::remove_all(dir, ec); }
  } cleanup{scratch};
  std::error_code ec;
  fs::remove_all(scratch, ec);
  fs::create_directories(scratch, ec);
  if (ec) throw io::IoError(scratch.string() + ": cannot create (" + ec.message() + ")");
  for (std::size_t i = 0; i < pngs.size(); ++i) {
    fs::create_symlink(fs::absolute(pngs[i]), scratch / fmt::format("frame_{:06d}.png", i), ec);
    if (ec) throw io::IoError(scratch.string() + ": cannot link the frames (" + ec.message() + ")");
  }

  const std::string rate = std::to_string(fps), input = (scratch / "frame_%06d.png").string(), output = partial.string();
  std::vector<std::string> args{ffmpeg->string(), "-nostdin", "-y", "-loglevel", "error", "-framerate", rate,
                                "-i", input, "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
                                "-pix_fmt", "yuv420p", "-crf", "20", output};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw io::IoError(fmt::format("{}: cannot start ffmpeg ({})", movie.string(), std::strerror(spawned)));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw io::IoError(movie.string() + ": lost track of ffmpeg");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !fs::is_regular_file(partial)) {
    std::ifstream in(log);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.size() > 600) text = "..." + text.substr(text.size() - 600);
    throw io::IoError(fmt::format("{}: ffmpeg failed (status {}): {}", movie.string(),
                                  WIFEXITED(status) ? WEXITSTATUS(status) : -1, text));
  }
  fs::rename(partial, movie, ec);
  if (ec) throw io::IoError(movie.string() + ": cannot move the finished movie into place (" + ec.message() + ")");
}

}  // namespace swirl::render
