// `swirl bench bh-opt`: the suite that runs the programs built at -O0 .. -O3
// (apps/bh_opt). The default build leaves those programs out, so the suite's
// own logic is tested with stand-ins that report fixed times (the ratios are
// then known exactly: a check of the arithmetic, not a timing); the real
// programs are run when they have been built (cmake --build build --target
// swirl_bh_opt), and the test says it skipped otherwise.
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "cli/cli_support.hpp"

namespace {

// The CSV as one map per row, keyed by column.
std::vector<std::map<std::string, std::string>> read_rows(const fs::path& p) {
  std::istringstream in(slurp(p));
  std::string line;
  std::vector<std::map<std::string, std::string>> rows;
  if (!std::getline(in, line)) return rows;
  const auto header = csv_cells(line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto cells = csv_cells(line);
    EXPECT_EQ(cells.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

const std::vector<std::string> kColumns{"particles", "source", "scheme",   "threads",  "iterations", "runs",
                                        "ms_o0",     "ms_o1",  "ms_o2",    "ms_o3",    "ratio_o0",   "ratio_o1",
                                        "ratio_o2",  "spread", "same_walk", "config"};

class BenchBhOpt : public Cli {
 protected:
  // A stand-in for swirl_bh_opt_O<level>: the real program's two CSV lines,
  // `seconds` as the run's time, its level as `reported`.
  void stand_in(const fs::path& dir, int level, double seconds, const std::string& reported, int status = 0) {
    fs::create_directories(dir);
    const auto p = dir / ("swirl_bh_opt_O" + std::to_string(level));
    std::ofstream(p) << "#!/bin/sh\n"
                     << "echo 'level,compiler,scheme,particles,threads,iterations,opening,seconds,tree_seconds,"
                        "force_seconds,update_seconds,nodes_visited,trees'\n"
                     << "echo \"" << reported << ",\\\"g++ stand-in\\\",$2,$4,$8,$6,0.5," << seconds
                     << ",0,0,0,700,5\"\n"
                     << "exit " << status << "\n";
    fs::permissions(p, fs::perms::owner_all);
  }
  void stand_ins(const fs::path& dir) {
    stand_in(dir, 0, 8.0, "O0");
    stand_in(dir, 1, 2.5, "O1");
    stand_in(dir, 2, 2.2, "O2");
    stand_in(dir, 3, 2.0, "O3");
  }
};

TEST_F(BenchBhOpt, MissingProgramsAreNamedWithTheCommandThatBuildsThem) {
  const auto empty = dir_ / "empty";
  fs::create_directories(empty);
  const Result r = swirl("bench bh-opt --quick --threads 1 --bin-dir " + empty.string() + " --out " + (dir_ / "o").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find((empty / "swirl_bh_opt_O0").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((empty / "swirl_bh_opt_O3").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cmake --build"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--target swirl_bh_opt"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o" / "bh-opt.csv"));
}

TEST_F(BenchBhOpt, TableFromTheProgramsOutputBesideThePapersRows) {
  const auto bin = dir_ / "bin";
  stand_ins(bin);
  const Result r = swirl("bench bh-opt --quick --threads 1,2 --schemes subtree,subdomain --bin-dir " + bin.string() +
                         " --out " + (dir_ / "o").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_rows(dir_ / "o" / "bh-opt.csv");
  // 2 schemes x 2 thread counts, then the paper's 1, 4 and 8 SPEs at N = 1024.
  ASSERT_EQ(rows.size(), 7u);
  for (const auto& col : kColumns) EXPECT_TRUE(rows[0].count(col)) << col;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& row = rows[i];
    EXPECT_EQ(row.at("source"), "swirl");
    EXPECT_EQ(row.at("particles"), "1024");
    // ms per iteration (--quick: 1 iteration) and the ratios of the stand-ins' fixed times.
    EXPECT_DOUBLE_EQ(std::stod(row.at("ms_o0")), 8000.0);
    EXPECT_DOUBLE_EQ(std::stod(row.at("ms_o3")), 2000.0);
    EXPECT_NEAR(std::stod(row.at("ratio_o0")), 4.0, 1e-12);
    EXPECT_NEAR(std::stod(row.at("ratio_o1")), 1.25, 1e-12);
    EXPECT_NEAR(std::stod(row.at("ratio_o2")), 1.1, 1e-12);
    EXPECT_EQ(row.at("same_walk"), "yes");
    EXPECT_EQ(row.at("spread"), "") << "one run per level: no spread to report";
  }
  EXPECT_EQ(rows[0].at("scheme"), "subtree");
  EXPECT_EQ(rows[2].at("scheme"), "subdomain");
  // The paper's rows: Table 2 at 1024 particles, divided by its 50 iterations; 1 SPE: 6.70 / 4.18.
  EXPECT_EQ(rows[4].at("source"), "paper");
  EXPECT_EQ(rows[4].at("threads"), "1");
  EXPECT_NEAR(std::stod(rows[4].at("ms_o0")), 134.0, 1e-9);
  EXPECT_NEAR(std::stod(rows[4].at("ratio_o0")), 6.70 / 4.18, 1e-12);
  EXPECT_NEAR(std::stod(rows[4].at("ratio_o1")), 4.34 / 4.18, 1e-12);
  EXPECT_EQ(rows[6].at("threads"), "8");
  const std::string json = slurp(dir_ / "o" / "bh-opt.json");
  EXPECT_NE(json.find("g++ stand-in"), std::string::npos) << "the programs' compiler is recorded";
  EXPECT_NE(r.out.find("none/-O1 = 1.75"), std::string::npos) << "the paper's text figure, from Table 2";
}

TEST_F(BenchBhOpt, AProgramReportingAnotherLevelIsRefused) {
  const auto bin = dir_ / "bin";
  stand_ins(bin);
  stand_in(bin, 2, 2.2, "O3");
  const Result r = swirl("bench bh-opt --quick --threads 1 --bin-dir " + bin.string() + " --out " + (dir_ / "o").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("swirl_bh_opt_O2 reports level O3"), std::string::npos) << r.err;
}

TEST_F(BenchBhOpt, AFailingProgramIsNamed) {
  const auto bin = dir_ / "bin";
  stand_ins(bin);
  stand_in(bin, 1, 2.5, "O1", 3);
  const Result r = swirl("bench bh-opt --quick --threads 1 --bin-dir " + bin.string() + " --out " + (dir_ / "o").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("swirl_bh_opt_O1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exit status 3"), std::string::npos) << r.err;
}

// The real programs, if built: every level walks the same tree (the four
// builds compute the same thing), and the report is complete.
TEST_F(BenchBhOpt, RealProgramsQuick) {
  const fs::path bin = fs::path(SWIRL_CLI).parent_path();
  for (int level = 0; level < 4; ++level)
    if (!fs::exists(bin / ("swirl_bh_opt_O" + std::to_string(level))))
      GTEST_SKIP() << "not built: cmake --build " << bin.string() << " --target swirl_bh_opt";
  const Result r = swirl("bench bh-opt --quick --threads 1,2 --out " + (dir_ / "o").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_rows(dir_ / "o" / "bh-opt.csv");
  // The default scheme (subtree) on 1 and 2 threads, then the paper's 1, 4 and 8 SPEs.
  ASSERT_EQ(rows.size(), 5u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(rows[i].at("scheme"), "subtree");
    EXPECT_EQ(rows[i].at("same_walk"), "yes") << rows[i].at("config");
    for (const char* col : {"ms_o0", "ms_o1", "ms_o2", "ms_o3", "ratio_o0", "ratio_o1", "ratio_o2"})
      EXPECT_GT(std::stod(rows[i].at(col)), 0) << col;
  }
  EXPECT_TRUE(fs::exists(dir_ / "o" / "bh-opt.json"));
  EXPECT_TRUE(fs::exists(dir_ / "o" / "bh-opt.md"));
  EXPECT_TRUE(fs::exists(dir_ / "o" / "bh-opt.png"));
}

}  // namespace
