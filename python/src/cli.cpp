// swirl._swirl.cli: the command-line tool in this process (apps/swirl/run_cli.hpp),
// for swirl.cli(), swirl.bench() and the `swirl` command pip installs.
//
// What the tool changes that a Python process keeps is put back afterwards:
// `swirl run` installs its own SIGINT/SIGTERM handlers (stop after the step,
// write a checkpoint), which would otherwise replace Python's KeyboardInterrupt;
// the bench suites and --threads set the thread count. The GIL is released
// while the tool runs, as while a Simulation steps.
#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "../../apps/swirl/run_cli.hpp"
#include "bindings.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::python {
namespace {

// Restores the signal handlers and the thread count on every exit path.
class ProcessStateGuard {
 public:
  ProcessStateGuard() : threads_(parallel::thread_count()) {
    sigaction(SIGINT, nullptr, &interrupt_);
    sigaction(SIGTERM, nullptr, &terminate_);
  }
  ~ProcessStateGuard() {
    sigaction(SIGINT, &interrupt_, nullptr);
    sigaction(SIGTERM, &terminate_, nullptr);
    parallel::set_thread_count(threads_);
  }
  ProcessStateGuard(const ProcessStateGuard&) = delete;
  ProcessStateGuard& operator=(const ProcessStateGuard&) = delete;

 private:
  int threads_;
  struct sigaction interrupt_ {};
  struct sigaction terminate_ {};
};

int run_tool(const std::vector<std::string>& args) {
  std::vector<std::string> words;
  words.reserve(args.size() + 1);
  words.emplace_back("swirl");
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);

  ProcessStateGuard guard;
  int status = 0;
  {
    nb::gil_scoped_release release;
    status = cli::run_cli(static_cast<int>(words.size()), argv.data());
    // The tool writes with C stdio; Python's own stdout is flushed by the caller.
    std::fflush(stdout);
    std::fflush(stderr);
  }
  return status;
}

}  // namespace

void bind_cli(nb::module_& m) {
  m.def("cli", &run_tool, nb::arg("args"));
}

}  // namespace swirl::python
