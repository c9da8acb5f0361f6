// Runs into a run folder, as `swirl run` makes them: sim::run_scene with its
// frame writer, diagnostics log, checkpoints and resume (sim/run.cpp), the GIL
// released while it runs. Between steps the progress hook takes the GIL for a
// moment: a pending signal (Ctrl-C) or an exception from the Python progress
// callback asks the run to stop after the current step, as SIGINT does in the
// CLI (a checkpoint is written), and is raised once run_scene returned.
#include <atomic>
#include <filesystem>
#include <optional>
#include <string>

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include "bindings.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/run.hpp"

namespace swirl::python {
namespace {

nb::dict to_dict(const std::vector<std::pair<std::string, double>>& values) {
  nb::dict d;
  for (const auto& [k, v] : values) d[k.c_str()] = v;
  return d;
}

nb::list to_list(const std::vector<std::string>& lines) {
  nb::list l;
  for (const auto& s : lines) l.append(s);
  return l;
}

// The closing summary, with the keys of `swirl run --summary-json`.
nb::dict summary_dict(const sim::RunSummary& s) {
  nb::dict d;
  d["scene"] = s.scene_file;
  d["precision"] = s.precision;
  d["out_dir"] = s.out_dir.string();
  d["threads"] = s.threads;
  d["particles"] = s.particles;
  d["steps"] = s.steps;
  d["first_step"] = s.first_step;
  d["sim_time"] = s.sim_time;
  d["time_unit"] = s.time_unit;
  d["wall_seconds"] = s.wall_seconds;
  d["steps_per_second"] = s.steps_per_second;
  d["phases"] = to_dict(s.phases);
  d["bytes_per_particle"] = s.bytes_per_particle;
  d["frames"] = s.frames;
  d["metrics"] = to_dict(s.metrics);
  d["error"] = s.error;
  d["blow_up"] = s.blow_up;
  d["interrupted"] = s.interrupted;
  d["last_checkpoint"] = s.last_checkpoint.string();
  d["warnings"] = to_list(s.warnings);
  d["failed_checks"] = to_list(s.failed_checks);
  return d;
}

struct RunArgs {
  std::optional<std::uint64_t> steps;
  std::optional<double> until;
  int threads = 0;
  bool overwrite = false;
  std::optional<double> checkpoint_every;
  std::optional<std::uint64_t> checkpoint_every_steps;
  std::size_t checkpoint_keep = 2;
  std::string on_blowup = "stop";
};

nb::dict run(const scene::Scene& scene, const std::string& out_dir, bool resume, const RunArgs& a, nb::object progress) {
  sim::RunOptions options;
  options.out_dir = out_dir;
  options.resume = resume;
  options.steps = a.steps;
  options.until = a.until;
  options.threads = a.threads;
  options.overwrite = a.overwrite;
  options.checkpoint_every = a.checkpoint_every;
  options.checkpoint_every_steps = a.checkpoint_every_steps;
  options.checkpoint_keep = a.checkpoint_keep;
  if (a.on_blowup == "stop") options.on_blow_up = OnBlowUp::Stop;
  else if (a.on_blowup == "warn") options.on_blow_up = OnBlowUp::Warn;
  else if (a.on_blowup == "off") options.on_blow_up = OnBlowUp::Off;
  else throw nb::value_error(("on_blowup '" + a.on_blowup + "': give \"stop\", \"warn\" or \"off\"").c_str());
  std::atomic<bool> stop{false};
  options.stop = &stop;
  std::optional<nb::python_error> raised;  // touched with the GIL held only
  auto on_progress = [&](const sim::RunProgress& p) {
    nb::gil_scoped_acquire gil;
    if (raised) return;
    try {
      check_signals();
      if (!progress.is_none()) {
        nb::dict d;
        d["step"] = p.step;
        d["first_step"] = p.first_step;
        d["total_steps"] = p.total_steps;
        d["time"] = p.sim_time;
        d["wall_seconds"] = p.wall_seconds;
        nb::object r = progress(d);
        if (r.is(nb::bool_(false))) stop = true;
      }
    } catch (nb::python_error& e) {
      raised.emplace(std::move(e));
      stop = true;
    }
  };
  sim::RunSummary summary;
  {
    nb::gil_scoped_release release;
    summary = sim::run_scene(scene, options, on_progress);
  }
  if (raised) throw std::move(*raised);
  return summary_dict(summary);
}

}  // namespace

void bind_run(nb::module_& m) {
  m.def(
      "run_scene",
      [](const PyScene& s, const std::string& out_dir, bool resume, std::optional<std::uint64_t> steps,
         std::optional<double> until, int threads, bool overwrite, std::optional<double> checkpoint_every,
         std::optional<std::uint64_t> checkpoint_every_steps, std::size_t checkpoint_keep, const std::string& on_blowup,
         nb::object progress) {
        return run(s.scene, out_dir, resume,
                   RunArgs{steps, until, threads, overwrite, checkpoint_every, checkpoint_every_steps, checkpoint_keep,
                           on_blowup},
                   progress);
      },
      nb::arg("scene"), nb::arg("out_dir"), nb::arg("resume"), nb::arg("steps").none(), nb::arg("until").none(),
      nb::arg("threads"), nb::arg("overwrite"), nb::arg("checkpoint_every").none(),
      nb::arg("checkpoint_every_steps").none(), nb::arg("checkpoint_keep"), nb::arg("on_blowup"),
      nb::arg("progress").none());
}

}  // namespace swirl::python
