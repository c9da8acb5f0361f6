// `swirl bench`: printing and writing a suite's report (bench.hpp), and the
// plots, drawn by Debian's python3-matplotlib from the CSV the suite wrote.
#include <omp.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench.hpp"
#include "swirl/config.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::cli::bench {
namespace {

namespace fs = std::filesystem;

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", int(c));
        else out += c;
    }
  }
  return out + "\"";
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// 15 significant digits: every figure measured or typed, without the binary
// noise of derived ones (100 × 0.07 = 7.000000000000001).
std::string csv_number(double value) { return fmt::format("{:.15g}", value); }

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        auto s = line.substr(colon + 1);
        s.erase(0, s.find_first_not_of(' '));
        return s;
      }
    }
  }
  return "unknown";
}

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string table_file(const SuiteReport& r, const Table& t) {
  return t.name.empty() ? r.suite + ".csv" : r.suite + "_" + t.name + ".csv";
}

const Table& find_table(const SuiteReport& r, const std::string& name) {
  for (const auto& t : r.tables)
    if (t.name == name) return t;
  throw std::logic_error("bench: plot refers to a missing table '" + name + "'");
}

// The plotting program: reads a JSON spec (argv[1]) naming CSV files,
// columns, filters and groups, draws one panel per entry and saves the PNG
// atomically (temporary name, then rename).
const char* kPlotScript = R"PY(
import csv, json, math, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

spec = json.load(open(sys.argv[1]))
panels = spec["panels"]
fig, axes = plt.subplots(1, len(panels), figsize=(8.8 * len(panels), 4.8), squeeze=False)
for ax, p in zip(axes[0], panels):
    firsts = []
    for s in p["series"]:
        rows = list(csv.DictReader(open(s["csv"], newline="")))
        rows = [r for r in rows if all(r.get(k) == v for k, v in s["filter"])]
        groups = {}
        for r in rows:
            if r.get(p["x"], "") == "" or r.get(s["y"], "") == "":
                continue
            key = r[s["group"]] if s["group"] else ""
            groups.setdefault(key, []).append((float(r[p["x"]]), float(r[s["y"]])))
        for key, pts in groups.items():
            pts.sort()
            label = s["label"] + (" " + s["group"] + "=" + key if s["group"] else "")
            ax.plot([a for a, _ in pts], [b for _, b in pts], marker="o", label=label)
            firsts.append(pts[0])
    for q in p["points"]:
        ax.plot(q["x"], q["y"], marker="s", linestyle=":", label=q["label"])
    if p["guides"] and firsts:
        x0, y0 = min(firsts)
        xs = sorted({x for s in ax.get_lines() for x in s.get_xdata()})
        if x0 > 0 and len(xs) > 1:
            ax.plot(xs, [y0 for x in xs], "k--", linewidth=0.8, label="O(N) (constant per particle)")
            ax.plot(xs, [y0 * math.log(x) / math.log(x0) for x in xs], "k:", linewidth=0.8,
                    label="O(N log N)")
    if p["logx"]:
        ax.set_xscale("log")
    if p["logy"]:
        ax.set_yscale("log")
    ax.set_xlabel(p["xlabel"])
    ax.set_ylabel(p["ylabel"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))  # beside the data, never over it
fig.suptitle(spec["title"], fontsize=10)
fig.tight_layout()
out = spec["png"]
tmp = out + ".tmp.png"
fig.savefig(tmp, dpi=90)
os.replace(tmp, out)
)PY";

std::string plot_spec(const SuiteReport& r, const Plot& plot, const fs::path& dir) {
  std::string panels;
  for (const auto& p : plot.panels) {
    std::string series;
    for (const auto& s : p.series) {
      find_table(r, s.table);
      std::string filter;
      for (const auto& [k, v] : s.filter) filter += fmt::format("{}[{}, {}]", filter.empty() ? "" : ", ", json_string(k), json_string(v));
      series += fmt::format("{}{{\"csv\": {}, \"y\": {}, \"label\": {}, \"filter\": [{}], \"group\": {}}}",
                            series.empty() ? "" : ", ", json_string((dir / table_file(r, find_table(r, s.table))).string()),
                            json_string(s.y), json_string(s.label), filter, json_string(s.group));
    }
    std::string points;
    for (const auto& q : p.points) {
      std::string xs, ys;
      for (double x : q.x) xs += fmt::format("{}{}", xs.empty() ? "" : ", ", x);
      for (double y : q.y) ys += fmt::format("{}{}", ys.empty() ? "" : ", ", y);
      points += fmt::format("{}{{\"label\": {}, \"x\": [{}], \"y\": [{}]}}", points.empty() ? "" : ", ",
                            json_string(q.label), xs, ys);
    }
    panels += fmt::format(
        "{}{{\"x\": {}, \"xlabel\": {}, \"ylabel\": {}, \"logx\": {}, \"logy\": {}, \"guides\": {}, \"series\": [{}], "
        "\"points\": [{}]}}",
        panels.empty() ? "" : ", ", json_string(p.x), json_string(p.xlabel), json_string(p.ylabel), p.logx, p.logy,
        p.complexity_guides, series, points);
  }
  return fmt::format("{{\"png\": {}, \"title\": {}, \"panels\": [{}]}}\n", json_string((dir / plot.file).string()),
                     json_string(plot.title), panels);
}

// Draws every plot; false (after saying why and how to fix it) if the tool is missing.
bool draw_plots(const SuiteReport& r, const fs::path& dir) {
  if (r.plots.empty()) return true;
  const char* env = std::getenv("SWIRL_PLOT_PYTHON");
  const std::string python = env && *env ? env : "/usr/bin/python3";
  const fs::path script = dir / (".plot_" + r.suite + ".py");
  io::write_file_atomic(script, kPlotScript);
  bool ok = true;
  for (const auto& plot : r.plots) {
    const fs::path spec = dir / (".plot_" + r.suite + ".json");
    io::write_file_atomic(spec, plot_spec(r, plot, dir));
    const std::string cmd = fmt::format("'{}' '{}' '{}' 2>&1", python, script.string(), spec.string());
    std::FILE* pipe = ::popen(cmd.c_str(), "r");
    std::string output;
    int status = -1;
    if (pipe) {
      char buf[512];
      while (std::fgets(buf, sizeof buf, pipe)) output += buf;
      status = ::pclose(pipe);
    }
    std::error_code ec;
    fs::remove(spec, ec);
    if (!(pipe && WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
      fmt::print(stderr,
                 "swirl bench: could not draw {} with {} (matplotlib): {}\n"
                 "  the CSV and JSON are written; to get the plots install Debian's python3-matplotlib\n"
                 "  (sudo apt-get install python3-matplotlib, or `make deps`) and run the suite again\n",
                 plot.file, python, output.empty() ? "the interpreter did not run" : output);
      ok = false;
      break;
    }
  }
  std::error_code ec;
  fs::remove(script, ec);
  return ok;
}

}  // namespace

std::vector<int> thread_counts(const CommonArgs& args) {
  if (!args.threads.empty()) return args.threads;
  std::vector<int> t;
  for (int i = 1; i <= omp_get_num_procs(); ++i) t.push_back(i);
  return t;
}

Cell number(double value, int decimals) {
  if (!std::isfinite(value)) return none();
  return {csv_number(value), fmt::format("{:.{}f}", value, decimals), true, value};
}

Cell significant(double value, int digits) {
  if (!std::isfinite(value)) return none();
  return {csv_number(value), fmt::format("{:.{}g}", value, digits), true, value};
}

Cell integer(long long value) {
  return {fmt::format("{}", value), fmt::format("{}", value), true, static_cast<double>(value)};
}

Cell text(std::string value) { return {value, value, false, 0}; }

Cell none() { return {"", "–", false, 0}; }

void Table::add(std::vector<Cell> row) {
  if (row.size() != columns.size())
    throw std::logic_error(fmt::format("bench table {}: row of {} cells for {} columns", name, row.size(), columns.size()));
  rows.push_back(std::move(row));
}

std::string Table::markdown() const {
  std::string s = "|";
  for (const auto& c : columns) s += fmt::format(" {} |", c.header);
  s += "\n|";
  for (std::size_t i = 0; i < columns.size(); ++i) s += "---|";
  s += "\n";
  for (const auto& row : rows) {
    s += "|";
    for (const auto& c : row) s += fmt::format(" {} |", c.md);
    s += "\n";
  }
  return s;
}

std::string Table::csv() const {
  std::string s;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i) s += ',';
    s += csv_field(columns[i].key);
  }
  s += "\n";
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (i) s += ',';
      s += csv_field(row[i].csv);
    }
    s += "\n";
  }
  return s;
}

void progress(const std::string& line) {
  fmt::print(stderr, "{}\n", line);
  std::fflush(stderr);
}

fs::path output_dir(const CommonArgs& args, const std::string& suite) {
  // By default a real run replaces the committed results; a quick one never does.
  return !args.out.empty() ? fs::path(args.out)
         : args.quick      ? fs::path("out") / "bench-quick" / suite
                           : fs::path("bench") / "results" / suite;
}

int publish(const SuiteReport& r, const CommonArgs& args) {
  const fs::path dir = output_dir(args, r.suite);
  io::ensure_writable_directory(dir);
  const std::string date = utc_now(), cpu = cpu_model();
  const int processors = omp_get_num_procs();
  std::string threads;
  for (int t : thread_counts(args)) threads += fmt::format("{}{}", threads.empty() ? "" : ",", t);

  // Markdown: the same text on the terminal and in <suite>.md.
  std::string md = fmt::format("### {} (`swirl bench {}`)\n\n", r.title, r.suite);
  md += fmt::format("Command: `{}`  \nMachine: {}, {} logical processors; {} {}, git {}; threads {}; {}{}\n\n",
                    args.command_line, cpu, processors, SWIRL_COMPILER, SWIRL_BUILD_TYPE, SWIRL_GIT_REVISION, threads,
                    date, args.quick ? "; **--quick** (tiny sizes: not a measurement)" : "");
  if (!r.parameters.empty()) {
    md += "Parameters:";
    for (const auto& [k, v] : r.parameters) md += fmt::format(" {} = {};", k, v);
    md.back() = '\n';
    md += "\n";
  }
  for (const auto& t : r.tables) {
    if (!t.title.empty()) md += fmt::format("**{}**\n\n", t.title);
    if (t.csv_only) {
      md += fmt::format("{} rows in `{}` (plotted below).\n\n", t.rows.size(), table_file(r, t));
      continue;
    }
    md += t.markdown();
    md += "\n";
  }
  if (!r.notes.empty()) md += fmt::format("{}\n", r.notes);
  std::string images;
  for (const auto& p : r.plots) images += fmt::format("![{}]({})\n\n", p.title, p.file);

  // CSV and JSON.
  for (const auto& t : r.tables) io::write_file_atomic(dir / table_file(r, t), t.csv());
  std::string json = fmt::format(
      "{{\n  \"suite\": {},\n  \"title\": {},\n  \"command\": {},\n  \"date\": {},\n  \"machine\": {{\"cpu\": {}, "
      "\"logical_processors\": {}}},\n  \"build\": {{\"swirl\": {}, \"compiler\": {}, \"build_type\": {}, "
      "\"git_revision\": {}}},\n  \"threads\": [{}],\n  \"quick\": {},\n  \"parameters\": {{",
      json_string(r.suite), json_string(r.title), json_string(args.command_line), json_string(date), json_string(cpu),
      processors, json_string(SWIRL_VERSION), json_string(SWIRL_COMPILER), json_string(SWIRL_BUILD_TYPE),
      json_string(SWIRL_GIT_REVISION), threads, args.quick);
  for (std::size_t i = 0; i < r.parameters.size(); ++i)
    json += fmt::format("{}{}: {}", i ? ", " : "", json_string(r.parameters[i].first), json_string(r.parameters[i].second));
  json += "},\n  \"tables\": {";
  for (std::size_t ti = 0; ti < r.tables.size(); ++ti) {
    const auto& t = r.tables[ti];
    json += fmt::format("{}\n    {}: {{\"file\": {}, \"rows\": [", ti ? "," : "", json_string(t.name.empty() ? "main" : t.name),
                        json_string(table_file(r, t)));
    for (std::size_t ri = 0; ri < t.rows.size(); ++ri) {
      json += ri ? ",\n      {" : "\n      {";
      for (std::size_t c = 0; c < t.columns.size(); ++c) {
        const Cell& cell = t.rows[ri][c];
        const std::string value = cell.numeric ? cell.csv : cell.csv.empty() ? "null" : json_string(cell.csv);
        json += fmt::format("{}{}: {}", c ? ", " : "", json_string(t.columns[c].key), value);
      }
      json += "}";
    }
    json += "]}";
  }
  json += "\n  },\n  \"plots\": [";
  for (std::size_t i = 0; i < r.plots.size(); ++i) json += fmt::format("{}{}", i ? ", " : "", json_string(r.plots[i].file));
  json += "]\n}\n";
  io::write_file_atomic(dir / (r.suite + ".json"), json);

  const bool plotted = draw_plots(r, dir);
  io::write_file_atomic(dir / (r.suite + ".md"), md + (plotted ? images : ""));
  fmt::print("{}", md);
  fmt::print("Written to {}/: {}.csv, {}.json, {}.md{}\n", dir.string(), r.suite, r.suite, r.suite,
             r.plots.empty() ? "" : plotted ? fmt::format(" and {} PNG plot(s)", r.plots.size()) : " (no plots)");
  std::fflush(stdout);
  return 0;
}

}  // namespace swirl::cli::bench
