// `swirl bench`: the seeds' experiments as suites (bench.cpp registers them).
//
//   sph-table   thesis Tables 5.1, 5.3, Figures 5.2, 5.3, 5.5, 5.7  (bench_sph.cpp)
//   hash-stats  thesis Table 5.2 and the cost of the duplicate check (bench_sph.cpp)
//   bh-table    paper Table 2, Figures 9-13                          (bench_bh.cpp)
//   bh-lambda   paper Figures 14-15: λ against time and force error  (bench_bh.cpp)
//   bh-phases   paper Table 1: time per phase                         (bench_bh.cpp)
//   bh-opt      paper Table 2's none/-O1/-O2/-O3 columns               (bench_bh_opt.cpp)
//
// A suite measures, fills a SuiteReport (tables whose seed columns say where
// their figures come from, notes, plots) and publish() prints the tables as
// markdown and writes to --out DIR: <suite>.csv (and <suite>_<table>.csv for
// further tables), <suite>.json (the tables with the machine, compiler,
// threads, date and git revision), <suite>.md and the PNG plots. The seeds'
// figures come from bench_seeds.hpp only.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace swirl::cli::bench {

// Options every suite has.
struct CommonArgs {
  std::string out;           // empty: bench/results/<suite> (the committed results), out/bench-quick/<suite> with --quick
  bool quick = false;        // tiny sizes, for CI: checks the pipeline, not the speed
  std::vector<int> threads;  // thread counts; empty: 1 .. all processors
  std::string command_line;  // as typed, for the records
};

// Thread counts to use: the given ones, or 1 .. all processors.
std::vector<int> thread_counts(const CommonArgs& args);

// One table cell: its CSV text, its markdown text, and its value if numeric.
struct Cell {
  std::string csv;
  std::string md;
  bool numeric = false;
  double value = 0;
};
Cell number(double value, int decimals);          // fixed decimals in markdown, full precision in CSV
Cell significant(double value, int digits);      // `digits` significant digits in markdown
Cell integer(long long value);
Cell text(std::string value);
Cell none();                                      // no figure: empty in CSV, "–" in markdown

struct Column {
  std::string key;     // CSV and JSON name
  std::string header;  // markdown header (seed columns name their source)
};

struct Table {
  std::string name;  // "" for the suite's main table, else the CSV suffix
  std::string title;
  std::vector<Column> columns;
  std::vector<std::vector<Cell>> rows;
  // A long series (e.g. a curve over time): written to its CSV and plotted,
  // named in the markdown but not printed there.
  bool csv_only = false;
  // Appends a row; throws std::logic_error if its width is not the columns'.
  void add(std::vector<Cell> row);
  std::string markdown() const;
  std::string csv() const;
};

// A line plot drawn from a suite's CSV by Debian's python3-matplotlib.
struct PlotSeries {
  std::string table;  // which table's CSV ("" = main)
  std::string y;      // column
  std::string label;
  std::vector<std::pair<std::string, std::string>> filter;  // keep rows whose column has this CSV text
  std::string group;  // one line per distinct value of this column ("" = one line)
};
struct PlotPoints {  // fixed points, e.g. the seeds' figures
  std::string label;
  std::vector<double> x, y;
};
struct PlotPanel {
  std::string x, xlabel, ylabel;
  bool logx = false, logy = false;
  bool complexity_guides = false;  // dashed O(N) and O(N log N) through the first point
  std::vector<PlotSeries> series;
  std::vector<PlotPoints> points;
};
struct Plot {
  std::string file;  // PNG name in the output directory
  std::string title;
  std::vector<PlotPanel> panels;  // side by side
};

struct SuiteReport {
  std::string suite;  // "sph-table", ...
  std::string title;
  std::vector<std::pair<std::string, std::string>> parameters;  // name, value: printed and in the JSON
  std::vector<Table> tables;
  std::string notes;  // markdown after the tables: set-up, provenance, how figures map
  std::vector<Plot> plots;
};

// The output directory of `suite`: --out, or its default.
std::filesystem::path output_dir(const CommonArgs& args, const std::string& suite);

// Prints the report to stdout and writes its files (atomically) into the
// output directory. Plots that cannot be drawn (no /usr/bin/python3 with
// matplotlib; SWIRL_PLOT_PYTHON overrides the interpreter) are reported on
// stderr with how to install the tool; the data files are written anyway.
// Returns the exit status (0).
int publish(const SuiteReport& report, const CommonArgs& args);

// Progress line on stderr (the tables go to stdout).
void progress(const std::string& line);

// The suites.
struct SphTableArgs {
  std::vector<std::size_t> sizes{1000, 2000, 5000, 10000, 15000, 20000, 25000, 30000, 35000};
  std::vector<double> neighbours{15, 25};  // measured neighbours aimed at
  std::vector<std::string> strategies;     // sph.neighbour_search values; empty: the scene default
  int settle = 3000;                       // steps before timing: the thesis's 3000
  int steps = 0;                           // timed steps; 0: about 2·10⁶ particle-steps, 20..1000
};
struct HashStatsArgs {
  std::size_t particles = 15000;
  double neighbours = 25;
  std::size_t buckets = 24001;
  int settle = 500;
  int steps = 0;  // timed steps; 0: as sph-table
};
struct BhTableArgs {
  std::vector<std::size_t> sizes{1024, 2048, 4096, 8192, 16384, 32768};
  std::vector<std::string> schemes{"subdomain", "subdomain+paper", "subtree", "subtree+paper", "global"};
  int iterations = 50;
  double opening = 0.5;
};
struct BhLambdaArgs {
  std::vector<std::size_t> sizes{4096, 32768};
  std::vector<double> openings{0.3, 0.5, 0.7, 0.9};
  std::vector<std::string> schemes{"subdomain", "subtree", "global"};
  int iterations = 20;
};
struct BhPhasesArgs {
  std::vector<std::size_t> sizes{1024, 2048, 4096, 8192, 16384, 32768};
  std::vector<std::string> schemes{"subtree", "subtree+paper"};
  int iterations = 50;
  double opening = 0.5;
};

// bh-opt runs the programs swirl_bh_opt_O0 .. _O3 (apps/bh_opt: the same
// experiment built at each level), which the default build leaves out.
struct BhOptArgs {
  std::vector<std::size_t> sizes{1024, 2048, 4096, 8192, 16384, 32768};
  std::vector<std::string> schemes{"subtree"};  // Table 2's (inferred); subdomain doubles the time for the same story
  int iterations = 0;  // 0: 50 · 1024 / N, 2 .. 50 (the -O0 build is slow)
  int rounds = 3;      // runs per level, levels alternated; medians
  double opening = 0.5;
  std::string bin_dir;  // where the programs are; empty: beside the swirl executable
};

int run_sph_table(SphTableArgs args, const CommonArgs& common);
int run_hash_stats(HashStatsArgs args, const CommonArgs& common);
int run_bh_table(BhTableArgs args, const CommonArgs& common);
int run_bh_lambda(BhLambdaArgs args, const CommonArgs& common);
int run_bh_phases(BhPhasesArgs args, const CommonArgs& common);
int run_bh_opt(BhOptArgs args, const CommonArgs& common);

}  // namespace swirl::cli::bench
