// The exit statuses the README documents, each produced by the command that
// documents it: the README's "Exit status:" paragraph is parsed, and every
// status it names must be walked here (and nothing else be named there).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <set>
#include <thread>

#include "cli_support.hpp"

namespace {

const std::string kExamples = std::string(SWIRL_SOURCE_DIR) + "/examples/";

// Every number in the README paragraph that starts with "Exit status:".
std::set<int> documented_statuses() {
  const std::string readme = slurp(fs::path(SWIRL_SOURCE_DIR) / "README.md");
  const auto begin = readme.find("Exit status:");
  EXPECT_NE(begin, std::string::npos);
  if (begin == std::string::npos) return {};
  const std::string paragraph = readme.substr(begin, readme.find("\n\n", begin) - begin);
  std::set<int> statuses;
  // Whole words of digits (not std::regex: GCC 12 warns inside <regex> under the sanitizer build).
  auto is_word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (std::size_t i = 0; i < paragraph.size();) {
    if (!std::isdigit(static_cast<unsigned char>(paragraph[i])) || (i > 0 && is_word(paragraph[i - 1]))) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < paragraph.size() && std::isdigit(static_cast<unsigned char>(paragraph[end]))) ++end;
    if (end == paragraph.size() || !is_word(paragraph[end])) statuses.insert(std::stoi(paragraph.substr(i, end - i)));
    i = end;
  }
  return statuses;
}

class ExitStatus : public Cli {
 protected:
  // The status of a long run stopped by `sig` once its second frame exists.
  int interrupted_status(int sig, const std::string& name) {
    const auto out = dir_ / name;
    const pid_t child = fork();
    if (child < 0) return -1;
    if (child == 0) {
      const std::string cmd = std::string(SWIRL_CLI) + " run " + kExamples +
                              "plummer.toml --set particles.0.count=400 --set output.interval=0.125 --steps 100000 --out " +
                              out.string() + " >/dev/null 2>" + (dir_ / (name + ".err")).string();
      execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    for (int k = 0; k < 6000 && !fs::exists(out / "particles_000001.vtp"); ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(child, sig);
    int status = 0;
    waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

TEST_F(ExitStatus, EveryDocumentedStatusIsWhatTheCommandReturns) {
  std::set<int> walked;
  const auto expect = [&](int status, const Result& r, const std::string& what) {
    EXPECT_EQ(r.status, status) << what << "\n" << r.err;
    walked.insert(status);
  };
  const auto scene = write_scene("s.toml", R"([simulation]
dt = 0.01
steps = 10
[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]
[output]
interval = 0.05
[[particles]]
kind = "lattice"
min = [0.3, 0.3, 0.5]
max = [0.7, 0.7, 0.9]
spacing = 0.1
mass = 0.001
)");
  // 0: done.
  expect(0, swirl("run " + scene.string() + " --out " + (dir_ / "ok").string()), "a run");
  expect(0, swirl("render " + (dir_ / "ok").string() + " --size 96x96"), "a render");
  // 1: the run stopped (a particle shot through the wall); render: frames missing.
  const auto shot = write_scene("shot.toml", R"([simulation]
dt = 4e-4
end_time = 0.02
[box]
min = [0.0, 0.0, 0.0]
max = [0.5, 0.5, 0.5]
[sph]
neighbours = 20
rest_density = 1000.0
sound_speed = 20.0
viscosity = 0.5
negative_pressure = "zero"
[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [0.1, 0.1, 0.1]
spacing = 0.02
[[particles]]
kind = "list"
positions = [[0.45, 0.25, 0.4]]
velocities = [[300.0, 0.0, 0.0]]
mass = 0.008
)");
  expect(1, swirl("run " + shot.string() + " --out " + (dir_ / "shot").string()), "a blow-up");
  fs::remove(dir_ / "ok" / "particles_000000.vtp");
  expect(1, swirl("render " + (dir_ / "ok").string() + " --all --size 96x96"), "a missing frame");
  // 2: bad input, nothing run: flags, scene, output directory.
  expect(2, swirl("run " + scene.string() + " --no-such-flag"), "an unknown flag");
  expect(2, swirl("run " + (dir_ / "missing.toml").string()), "a missing scene");
  std::ofstream(dir_ / "file") << "x";
  expect(2, swirl("run " + scene.string() + " --out " + (dir_ / "file" / "sub").string()), "an unwritable --out");
  // 130 / 143: stopped by SIGINT / SIGTERM after writing a checkpoint.
  for (const auto& [sig, status] : {std::pair{SIGINT, 130}, std::pair{SIGTERM, 143}}) {
    const std::string name = "signal" + std::to_string(sig);
    const int got = interrupted_status(sig, name);
    if (got == 0) GTEST_SKIP() << "the run finished before the signal arrived";
    EXPECT_EQ(got, status) << slurp(dir_ / (name + ".err"));
    EXPECT_FALSE(fs::is_empty(dir_ / name / "checkpoints")) << "a checkpoint was written";
    walked.insert(status);
  }
  EXPECT_EQ(walked, documented_statuses()) << "the README's exit statuses and the walked ones differ";
}

}  // namespace
