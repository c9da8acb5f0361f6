// The swirl command-line tool, run as a user runs it.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <chrono>

#include "cli_support.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/vtp.hpp"

namespace fs = std::filesystem;

namespace {

const char* kSmallScene = R"(
[simulation]
precision = "double"
dt = 0.01
end_time = 0.5

[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]
restitution = 0.5

[output]
interval = 0.1
format = ["vtp", "csv"]

[[particles]]
kind = "lattice"
min = [0.2, 0.2, 0.5]
max = [0.8, 0.8, 0.9]
spacing = 0.1
mass = 0.001
)";

TEST_F(Cli, RunWritesFramesSeriesAndSummary) {
  const auto scene = write_scene("small.toml", kSmallScene);
  const auto out = dir_ / "out";
  const auto json = dir_ / "summary.json";
  const auto r = swirl("run " + scene.string() + " --threads 2 --out " + out.string() + " --summary-json " + json.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("steps per second"), std::string::npos) << r.out;

  // Frames at t = 0, 0.1, ..., 0.5, listed in the .pvd with their times.
  const auto entries = swirl::io::read_pvd(out / "particles.pvd");
  ASSERT_EQ(entries.size(), 6u);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    EXPECT_NEAR(entries[k].time, 0.1 * double(k), 1e-12);
    EXPECT_TRUE(fs::exists(out / entries[k].file)) << entries[k].file;
    EXPECT_TRUE(fs::exists(out / fs::path(entries[k].file).replace_extension(".csv")));
  }
  const auto last = swirl::io::read_vtp(out / entries.back().file);
  EXPECT_EQ(last.num_points, 6u * 6u * 4u);
  const auto z = last.points.values<double>();
  for (std::size_t i = 2; i < z.size(); i += 3) EXPECT_LT(z[i], 0.9);  // it fell

  const std::string summary = slurp(json);
  EXPECT_NE(summary.find("\"particles\": 144"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"steps\": 50"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"completed\": true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"forces\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"bytes_per_particle\": 128"), std::string::npos) << summary;  // 15 doubles + id
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "left-over " << e.path();
}

TEST_F(Cli, StepsAndSetOverrideTheScene) {
  const auto scene = write_scene("small.toml", kSmallScene);
  const auto json = dir_ / "s.json";
  auto r = swirl("run " + scene.string() + " --out " + (dir_ / "a").string() + " --steps 7 --summary-json " + json.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(json).find("\"steps\": 7,"), std::string::npos);
  r = swirl("run " + scene.string() + " --out " + (dir_ / "b").string() +
            " --set simulation.end_time=0.05 --set output.format='\"csv\"' --summary-json " + json.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(json).find("\"steps\": 5,"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "b" / "particles.pvd"));
  EXPECT_TRUE(fs::exists(dir_ / "b" / "particles_000000.csv"));
}

TEST_F(Cli, ABadSceneIsRefusedWithFileKeyAndReasonAndNothingIsWritten) {
  std::string text = kSmallScene;
  text.replace(text.find("dt = 0.01"), 9, "dt = -0.01");
  const auto scene = write_scene("bad.toml", text);
  const auto out = dir_ / "never";
  const auto r = swirl("run " + scene.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.toml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("simulation.dt"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, AMissingSceneFileIsAClearError) {
  const auto r = swirl("run " + (dir_ / "nope.toml").string() + " --out " + (dir_ / "o").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nope.toml"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Cli, AnUnwritableOutputDirectoryIsRefusedBeforeRunning) {
  const auto scene = write_scene("small.toml", kSmallScene);
  std::ofstream(dir_ / "file") << "x";
  const auto r = swirl("run " + scene.string() + " --out " + (dir_ / "file" / "sub").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("file/sub"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("steps per second"), std::string::npos);
}

TEST_F(Cli, RandomBoxReportsNeighboursAndWritesDiagnostics) {
  const std::string scene = std::string(SWIRL_SOURCE_DIR) + "/examples/random_box.toml";
  const auto out = dir_ / "rb";
  const auto json = dir_ / "rb.json";
  const auto r = swirl("run " + scene + " --set particles=3000 --steps 4 --threads 2 --out " + out.string() +
                       " --summary-json " + json.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("mean_neighbours"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("particles        3000"), std::string::npos) << r.out;
  const std::string summary = slurp(json);
  const auto at = summary.find("\"mean_neighbours\": ");
  ASSERT_NE(at, std::string::npos) << summary;
  const double neighbours = std::stod(summary.substr(at + 19));
  EXPECT_GT(neighbours, 18.0);  // 25 targeted; particles near the walls have fewer
  EXPECT_LT(neighbours, 27.0);
  // One diagnostics row per frame (t = 0 and the end), after the header.
  const std::string csv = slurp(out / "diagnostics.csv");
  EXPECT_EQ(csv.rfind("time,kinetic_energy", 0), 0u) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
}

TEST_F(Cli, HashStatsPrintsTable52) {
  const std::string scene = std::string(SWIRL_SOURCE_DIR) + "/examples/random_box.toml";
  auto r = swirl("hash-stats " + scene + " --set particles=3000");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* row : {"Hash table size", "Empty hash buckets", "collisions", "non-empty bucket", "Redundant",
                          "Duplicate interactions", "4801"})
    EXPECT_NE(r.out.find(row), std::string::npos) << row << "\n" << r.out;
  const auto plain = write_scene("small.toml", kSmallScene);
  r = swirl("hash-stats " + plain.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("[sph]"), std::string::npos) << r.err;
}

TEST_F(Cli, PlummerRunsWithEveryScheme) {
  const std::string scene = std::string(SWIRL_SOURCE_DIR) + "/examples/plummer.toml";
  for (const char* scheme : {"subdomain", "subtree", "global"}) {
    const auto out = dir_ / scheme;
    const auto r = swirl("run " + scene + " --set particles.0.count=600 --steps 3 --out " + out.string() +
                         " --set 'nbody.scheme=\"" + scheme + "\"'");
    ASSERT_EQ(r.status, 0) << scheme << ": " << r.err;
    EXPECT_NE(r.out.find("relative_energy_error"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("forces.tree_build"), std::string::npos) << r.out;
    const auto frames = swirl::io::read_pvd(out / "particles.pvd");
    ASSERT_EQ(frames.size(), 2u);
    const auto last = swirl::io::read_vtp(out / frames.back().file);
    ASSERT_TRUE(last.point_data.count("potential")) << scheme;
    for (double phi : last.point_data.at("potential").values<double>()) EXPECT_LT(phi, 0.0);
    const std::string csv = slurp(out / "diagnostics.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;  // header and two frames
  }
}

TEST_F(Cli, InfoNamesTheBuild) {
  const auto r = swirl("info");
  ASSERT_EQ(r.status, 0);
  for (const char* key : {"git revision", "build type", "compiler", "threads", "vector width"})
    EXPECT_NE(r.out.find(key), std::string::npos) << key;
}

// swirl view opens its page in the user's browser when one is at hand: with a
// display (DISPLAY) by default, with --open always also without one, never
// with --open never or over a bare terminal (SSH: the URL is printed). The
// browser here is a script, named by $BROWSER, that notes the URL it is given.
TEST_F(Cli, ViewOpensThePageInTheUsersBrowserWhenOneIsAtHand) {
  const auto scene = write_scene("small.toml", kSmallScene);
  const auto opened = dir_ / "opened.txt", browser = dir_ / "browser.sh";
  std::ofstream(browser) << "#!/bin/sh\necho \"$1\" >> " << opened.string() << "\n";
  fs::permissions(browser, fs::perms::owner_all);
  const auto lines_opened = [&] {
    const std::string text = fs::exists(opened) ? slurp(opened) : std::string();
    return std::count(text.begin(), text.end(), '\n');
  };
  // The script runs on after swirl has moved on: wait for its line.
  const auto wait_for_lines = [&](long n) {
    for (int k = 0; k < 200 && lines_opened() < n; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return lines_opened();
  };
  const std::string view = "view " + scene.string() + " --port 0 --paused --seconds 0.3";
  const std::string with_display = "env -u WAYLAND_DISPLAY DISPLAY=:77 BROWSER=" + browser.string() + " ";
  const std::string without = "env -u DISPLAY -u WAYLAND_DISPLAY BROWSER=" + browser.string() + " ";

  auto r = swirl(view, with_display);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  ASSERT_EQ(wait_for_lines(1), 1) << r.out;
  const std::string url = slurp(opened).substr(0, slurp(opened).find('\n'));
  EXPECT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  EXPECT_NE(r.out.find("live at " + url), std::string::npos) << "the page opened is the one printed: " << r.out;
  EXPECT_NE(r.out.find("swirl view: opened in " + browser.string()), std::string::npos) << r.out;

  r = swirl(view, without);  // a terminal without a display: the URL only
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("opened in"), std::string::npos) << r.out;
  r = swirl(view + " --open never", with_display);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("opened in"), std::string::npos) << r.out;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(lines_opened(), 1);

  // --open always without a display, and $BROWSER's "%s" standing for the URL.
  r = swirl(view + " --open always", "env -u DISPLAY -u WAYLAND_DISPLAY BROWSER='" + browser.string() + " --at=%s' ");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(wait_for_lines(2), 2);
  const std::string second = slurp(opened).substr(url.size() + 1);
  EXPECT_EQ(second.rfind("--at=http://127.0.0.1:", 0), 0u) << second;
  EXPECT_NE(r.out.find("swirl view: opened in " + browser.string() + " --at=%s"), std::string::npos) << r.out;
  EXPECT_EQ(swirl(view + " --open sometimes").status, 2) << "not one of auto, always, never";
}

TEST_F(Cli, UsageErrorsExitNonZero) {
  EXPECT_NE(swirl("").status, 0);
  EXPECT_NE(swirl("run").status, 0);
  EXPECT_NE(swirl("run x.toml --threads 0").status, 0);
}

}  // namespace
