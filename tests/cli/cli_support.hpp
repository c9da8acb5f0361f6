// Running the swirl binary from tests, as a user runs it.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string out, err;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// One CSV line's cells, split at commas outside double quotes (the quotes dropped).
inline std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) cells.emplace_back();
    else cells.back() += c;
  }
  return cells;
}

// A CSV file's rows (the header first).
inline std::vector<std::vector<std::string>> csv_rows(const fs::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(slurp(file));
  std::string line;
  while (std::getline(in, line)) rows.push_back(csv_cells(line));
  return rows;
}

// The index of a named column of a header row.
inline std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  const auto it = std::find(header.begin(), header.end(), name);
  EXPECT_NE(it, header.end()) << name;
  return static_cast<std::size_t>(it - header.begin());
}

// Every output file of two finished runs (frames, series, diagnostics),
// compared byte for byte; the run folders' own bookkeeping (the lock with its
// pid, the manifest with the run's identity) and the saved scene are not outputs.
inline void expect_same_outputs(const fs::path& a, const fs::path& b) {
  std::size_t compared = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    const auto name = e.path().filename().string();
    if (e.is_directory() || name == "scene.toml" || name == ".swirl.lock" || name == "manifest.txt") continue;
    ASSERT_TRUE(fs::exists(b / name)) << name;
    EXPECT_TRUE(slurp(e.path()) == slurp(b / name)) << name << " differs";
    ++compared;
  }
  EXPECT_GE(compared, 4u);
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swirl_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs the CLI with `args`; `prefix` goes before it on the shell line (an
  // environment variable, `timeout 60 `).
  Result swirl(const std::string& args, const std::string& prefix = "") {
    const auto out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = prefix + std::string(SWIRL_CLI) + " " + args + " >" + out.string() + " 2>" + err.string();
    Result r;
    const int raw = std::system(cmd.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  fs::path write_scene(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }

  fs::path dir_;
};


