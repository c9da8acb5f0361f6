// `swirl bench SUITE --quick`: every suite runs at tiny sizes and writes its
// CSV (every column, the expected rows, no NaN), JSON (with the build and
// machine records), markdown and valid PNG plots. Timings are never asserted.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_support.hpp"

namespace {

std::vector<std::string> split_line(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) {
      cells.push_back(cell);
      cell.clear();
    } else cell += c;
  }
  cells.push_back(cell);
  return cells;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

Csv read_csv(const fs::path& p) {
  std::istringstream in(slurp(p));
  Csv csv;
  std::string line;
  if (std::getline(in, line)) csv.header = split_line(line);
  while (std::getline(in, line))
    if (!line.empty()) csv.rows.push_back(split_line(line));
  return csv;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Every column present in order, `rows` rows of the header's width, no NaN or
// infinity anywhere, and at least one number in every listed numeric column.
void expect_csv(const fs::path& p, const std::vector<std::string>& columns, std::size_t rows,
                const std::vector<std::string>& numeric) {
  ASSERT_TRUE(fs::exists(p)) << p;
  const Csv csv = read_csv(p);
  EXPECT_EQ(csv.header, columns) << p;
  EXPECT_EQ(csv.rows.size(), rows) << p;
  for (const auto& row : csv.rows) {
    ASSERT_EQ(row.size(), csv.header.size()) << p;
    for (const auto& cell : row) {
      const std::string l = lower(cell);
      EXPECT_EQ(l.find("nan"), std::string::npos) << p << ": " << cell;
      EXPECT_EQ(l.find("inf"), std::string::npos) << p << ": " << cell;
    }
  }
  for (const auto& col : numeric) {
    const auto it = std::find(csv.header.begin(), csv.header.end(), col);
    ASSERT_NE(it, csv.header.end()) << p << ": " << col;
    const auto c = static_cast<std::size_t>(it - csv.header.begin());
    for (const auto& row : csv.rows) {
      char* end = nullptr;
      const double v = std::strtod(row[c].c_str(), &end);
      EXPECT_TRUE(end && *end == '\0' && !row[c].empty()) << p << ": " << col << " = '" << row[c] << "'";
      EXPECT_GE(v, 0) << p << ": " << col;
    }
  }
}

void expect_png(const fs::path& p) {
  ASSERT_TRUE(fs::exists(p)) << p;
  const std::string bytes = slurp(p);
  ASSERT_GT(bytes.size(), 8u + 25u) << p;
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << p;
  EXPECT_EQ(bytes.substr(12, 4), "IHDR") << p;
}

void expect_records(const fs::path& json, const std::string& suite) {
  ASSERT_TRUE(fs::exists(json)) << json;
  const std::string j = slurp(json);
  for (const char* key : {"\"suite\"", "\"date\"", "\"machine\"", "\"cpu\"", "\"logical_processors\"", "\"compiler\"",
                          "\"build_type\"", "\"git_revision\"", "\"threads\": [1,2]", "\"quick\": true", "\"tables\""})
    EXPECT_NE(j.find(key), std::string::npos) << json << " lacks " << key;
  EXPECT_NE(j.find("\"" + suite + "\""), std::string::npos);
  EXPECT_EQ(lower(j).find("nan"), std::string::npos);
}

class BenchCli : public Cli {
 protected:
  Result bench(const std::string& suite) {
    return swirl("bench " + suite + " --quick --threads 1,2 --out " + (dir_ / suite).string());
  }
};

TEST_F(BenchCli, SphTableQuick) {
  const Result r = bench("sph-table");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| N | k aimed |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Table 5.1, measured"), std::string::npos);
  EXPECT_NE(r.out.find("Table 5.3, simulated"), std::string::npos);
  const auto d = dir_ / "sph-table";
  // 2 sizes x 2 neighbour counts x 2 thread counts.
  expect_csv(d / "sph-table.csv",
             {"particles", "neighbours", "measured_neighbours", "strategy", "threads", "steps", "hz",
              "us_per_particle_step", "share_structure", "share_table", "share_search_density", "share_forces", "share_integrate",
              "share_other", "speedup", "efficiency", "thesis_ppc970_hz", "thesis_cell_1spe_hz", "thesis_cell_8spe_hz",
              "thesis_cell_8spe_efficiency", "sorts_per_step", "kf_structure", "kf_density", "kf_forces", "kf_integrate",
              "kf_step", "kf_noise", "share_neighbour_hashes"},
             8,
             {"particles", "measured_neighbours", "threads", "hz", "us_per_particle_step", "share_structure",
              "share_search_density", "share_forces", "share_integrate", "share_other", "speedup", "efficiency"});
  expect_csv(d / "sph-table_settle.csv",
             {"particles", "neighbours", "target", "initial_neighbours", "settled_neighbours", "settle_steps",
              "settle_seconds", "settle_warnings"},
             4, {"target", "initial_neighbours", "settled_neighbours"});
  // N = 1000 is a thesis row: its figures sit beside ours, 500 is not.
  const Csv csv = read_csv(d / "sph-table.csv");
  for (const auto& row : csv.rows) {
    EXPECT_EQ(row[0] == "1000", !row[16].empty()) << row[0];
    EXPECT_EQ(row[4] != "1", !row[25].empty()) << row[0];  // Karp-Flatt e of the whole step: p > 1 rows only
    EXPECT_EQ(row[3], "grid (scene default)") << "every row names its strategy";
  }
  expect_records(d / "sph-table.json", "sph-table");
  EXPECT_TRUE(fs::exists(d / "sph-table.md"));
  // The plots need Debian's python3-matplotlib (make deps installs it).
  // Figure 5.1: the neighbour count along the settling, 6 points (steps 0..5) per size and k.
  expect_csv(d / "sph-table_settling.csv", {"particles", "neighbours", "step", "mean_neighbours"}, 24,
             {"step", "mean_neighbours"});
  // Figure 5.4: the thesis's ratio where it has a row (N = 1000, k = 25); ours needs hash and grid runs.
  expect_csv(d / "sph-table_fig54.csv", {"particles", "neighbours", "hash_over_grid", "thesis_spe_over_ppc"}, 1,
             {"thesis_spe_over_ppc"});
  // Figure 5.6: one 1-thread row per size at the last k; section 4.5: the triad on each thread count, the
  // model on every row at the last k, pass by pass (6 passes + total), and the thesis's own figures (example + 9 rows).
  expect_csv(d / "sph-table_fig56.csv",
             {"particles", "neighbours", "strategy", "source", "share_hashing", "share_table", "share_neighbour_hashes",
              "share_search_density", "share_hash_search", "share_forces", "share_rest", "thesis_spe_hash_search"},
             2, {"share_hashing", "share_search_density", "share_hash_search", "thesis_spe_hash_search"});
  expect_csv(d / "sph-table_stream.csv",
             {"threads", "array_mib", "repetitions", "triad_gbs", "thesis_cell_practical_gbs"}, 2, {"triad_gbs"});
  expect_csv(d / "sph-table_bandwidth.csv",
             {"particles", "neighbours", "strategy", "threads", "hz", "measured_neighbours", "candidates",
              "bytes_access", "bytes_streamed", "gbs_access", "gbs_streamed", "triad_gbs", "fraction_access_pct",
              "fraction_streamed_pct", "thesis_bytes", "thesis_8spe_gbs", "thesis_8spe_fraction_pct"},
             4, {"candidates", "bytes_access", "bytes_streamed", "gbs_access", "fraction_access_pct"});
  expect_csv(d / "sph-table_bandwidth_passes.csv",
             {"pass", "thesis", "hash_access", "hash_streamed", "hash_precomputed_access", "grid_access",
              "grid_streamed"},
             7, {"thesis", "grid_access", "grid_streamed"});
  expect_csv(d / "sph-table_bandwidth_thesis.csv",
             {"case", "particles", "buckets", "neighbours", "hz", "bytes_per_particle", "gbs", "gbs_stated",
              "aligned_pct", "fraction_pct"},
             10, {"bytes_per_particle", "gbs", "aligned_pct"});
  for (const char* png : {"sph-table_cost.png", "sph-table_efficiency.png", "sph-table_subtasks.png",
                          "sph-table_settling.png", "sph-table_bandwidth.png"})
    expect_png(d / png);
}

TEST_F(BenchCli, HashStatsQuick) {
  const Result r = bench("hash-stats");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto d = dir_ / "hash-stats";
  expect_csv(d / "hash-stats.csv", {"statistic", "swirl", "thesis"}, 8, {"swirl", "thesis"});
  expect_csv(d / "hash-stats_check.csv",
             {"threads", "steps", "hz_check_on", "hz_check_after", "hz_check_off", "gain_check_off_pct",
              "gain_check_off_thesis_place_pct", "thesis_ppc970_gain_pct", "thesis_cell_gain_pct"},
             2, {"hz_check_on", "hz_check_after", "hz_check_off", "thesis_cell_gain_pct"});
  expect_records(d / "hash-stats.json", "hash-stats");
  EXPECT_NE(r.out.find("24001"), std::string::npos) << "the thesis's table size beside ours";
}

TEST_F(BenchCli, BhTableQuick) {
  const Result r = bench("bh-table");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto d = dir_ / "bh-table";
  // 2 sizes x 5 schemes (ours and the paper's splits) x 2 thread counts.
  expect_csv(d / "bh-table.csv",
             {"particles", "scheme", "threads", "iterations", "seconds", "us_per_particle_iteration", "tree_seconds",
              "force_seconds", "update_seconds", "nodes_visited", "trees", "speedup", "paper_speedup_p", "efficiency",
              "speedup_serial", "paper_over_xeon", "paper_1spe_s", "paper_4spe_s", "paper_8spe_s",
              "paper_speedup_8spe", "paper_trees"},
             20, {"seconds", "us_per_particle_iteration", "nodes_visited", "trees", "speedup", "efficiency", "speedup_serial"});
  // The enhanced over the initial scheme, ours and with the paper's splits: 2 sizes x 2 thread counts.
  expect_csv(d / "bh-table_enhanced_over_initial.csv", {"particles", "threads", "ours", "paper_splits", "paper"}, 4,
             {"ours", "paper_splits"});
  expect_records(d / "bh-table.json", "bh-table");
  for (const char* png : {"bh-table_cost.png", "bh-table_efficiency.png"}) expect_png(d / png);
}

TEST_F(BenchCli, BhLambdaQuick) {
  const Result r = bench("bh-lambda");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto d = dir_ / "bh-lambda";
  // 2 sizes x 4 lambdas x 3 schemes.
  expect_csv(d / "bh-lambda.csv",
             {"particles", "lambda", "scheme", "threads", "iterations", "ms_per_iteration", "nodes_visited",
              "error_median", "error_p99", "error_max", "speedup_serial", "paper_speedup_vs_xeon"},
             24, {"ms_per_iteration", "nodes_visited", "error_median", "error_p99", "error_max", "speedup_serial"});
  // The error grows with lambda and the percentiles are ordered (not a timing).
  const Csv csv = read_csv(d / "bh-lambda.csv");
  for (const auto& row : csv.rows) {
    EXPECT_LE(std::stod(row[7]), std::stod(row[8]));
    EXPECT_LE(std::stod(row[8]), std::stod(row[9]));
    EXPECT_GT(std::stod(row[7]), 0);
  }
  expect_records(d / "bh-lambda.json", "bh-lambda");
  expect_png(d / "bh-lambda.png");
}

// The FMM dimension of bh-scale: its rows beside Barnes-Hut's, the error
// falling with the order, and the same errors for 1 and 2 threads (the
// results are bit-identical; the times are never compared).
TEST_F(BenchCli, BhScaleQuickWithFmm) {
  const auto d = dir_ / "bh-scale";
  const Result r = swirl("bench bh-scale --quick --threads 1,2 --multipoles quadrupole --criteria barnes "
                         "--fmm-orders 2,4 --fmm-buckets 32 --out " + d.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // 2 sizes x (1 Barnes-Hut + 2 FMM orders) x 2 thread counts.
  expect_csv(d / "bh-scale.csv",
             {"particles", "precision", "method", "order", "multipole", "criterion", "walk", "opening", "bucket",
              "group", "config", "threads", "repeats", "ms_per_evaluation", "cpu_ms_per_evaluation", "ms_build", "ms_walk",
              "ns_per_particle",
              "minteractions_per_second", "error_median", "error_p99", "interactions", "nodes_visited", "leaves",
              "tree_bytes_per_particle", "total_bytes_per_particle", "sampled"},
             12, {"ms_per_evaluation", "cpu_ms_per_evaluation", "error_median", "error_p99", "interactions",
                  "nodes_visited"});
  const Csv csv = read_csv(d / "bh-scale.csv");
  std::map<std::string, std::string> error_at;  // size/method/order -> median error (1 thread)
  for (const auto& row : csv.rows) {
    const std::string key = row[0] + "/" + row[2] + "/" + row[3];
    if (row[11] == "1") error_at[key] = row[19];
  }
  ASSERT_EQ(error_at.size(), 6u);
  for (const auto& row : csv.rows) {
    EXPECT_EQ(row[19], error_at[row[0] + "/" + row[2] + "/" + row[3]]) << "threads " << row[11];
    if (row[2] == "fmm") {
      EXPECT_EQ(row[8], "32");
    }
  }
  for (const char* n : {"4096", "8192"})
    EXPECT_LT(std::stod(error_at[std::string(n) + "/fmm/4"]), std::stod(error_at[std::string(n) + "/fmm/2"])) << n;
  expect_records(d / "bh-scale.json", "bh-scale");
  expect_png(d / "bh_scale.png");
}

TEST_F(BenchCli, BhPhasesQuick) {
  const Result r = bench("bh-phases");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto d = dir_ / "bh-phases";
  expect_csv(d / "bh-phases.csv",
             {"particles", "scheme", "threads", "tree_ms", "force_ms", "update_ms", "other_ms", "total_ms",
              "force_overhead_ms", "tree_pct", "force_pct", "update_pct", "other_pct", "paper_tree_pct",
              "paper_force_pct", "paper_update_pct", "paper_sync_pct"},
             8, {"tree_ms", "force_ms", "update_ms", "other_ms", "total_ms", "tree_pct", "force_pct"});  // 2 sizes x 2 schemes x 2 threads
  // The paper's Table 1 as published: 11 rows and Table 2's per-iteration total.
  expect_csv(d / "bh-phases_paper.csv", {"phase", "kind", "n1024", "n2048", "n4096", "n8192", "n16384", "n32768"}, 12,
             {"n1024", "n32768"});
  EXPECT_NE(r.out.find("238.9 ms"), std::string::npos) << "the Table 1 / Table 2 mismatch is stated";
  // The figures of the paper's text around Table 1 (ours only where the sizes are the paper's).
  expect_csv(d / "bh-phases_text.csv", {"figure", "particles", "paper_pct", "ours_pct", "ours_is"}, 9, {"paper_pct"});
  expect_records(d / "bh-phases.json", "bh-phases");
}

TEST_F(BenchCli, WithoutThePlottingToolTheDataAreStillWritten) {
  const std::string cmd = "SWIRL_PLOT_PYTHON=/nonexistent/python3 ";
  const auto out = dir_ / "noplot";
  const auto log = dir_ / "log.txt";
  const int raw = std::system((cmd + SWIRL_CLI + " bench bh-table --quick --threads 1 --out " + out.string() + " >" +
                               log.string() + " 2>&1")
                                  .c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 0) << slurp(log);
  EXPECT_TRUE(fs::exists(out / "bh-table.csv"));
  EXPECT_TRUE(fs::exists(out / "bh-table.json"));
  EXPECT_FALSE(fs::exists(out / "bh-table_cost.png"));
  EXPECT_NE(slurp(log).find("python3-matplotlib"), std::string::npos) << slurp(log);
}

TEST_F(BenchCli, BadSchemeIsRefusedWithTheAllowedNames) {
  const Result r = swirl("bench bh-table --quick --schemes subdomain,bogus --out " + (dir_ / "bad").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bogus"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("subtree"), std::string::npos) << r.err;
}

}  // namespace
