// Runs into a run folder, as `swirl run` makes them: sim::run_scene with its
// frame writer, diagnostics log, checkpoints and resume (sim/run.cpp), the GIL
// released while it runs. Between steps the progress hook takes the GIL for a
// moment: a pending signal (Ctrl-C) or an exception from the Python progress
// callback asks the run to stop after the current step, as SIGINT does in the
// CLI (a checkpoint is written), and is raised once run_scene returned.
//
// Forces and a callback written in Python enter the run through its
// RunExtension (sim/run.hpp): the forces as solvers of the run's simulation,
// the callback as an observer that calls callback(sim) every N steps or every
// T of simulated time, where `sim` is a _swirl.Simulation on the run's own
// simulation (borrow_simulation), cut off when the run ends.
#include <atomic>
#include <filesystem>
#include <optional>
#include <string>

#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "swirl/render/fluid_surface.hpp"
#include "swirl/scene/load.hpp"
#include "swirl/sim/observer.hpp"
#include "swirl/sim/run.hpp"
#include "swirl/sim/simulation.hpp"

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

// What Python adds to a run, and what it left to raise. Touched with the GIL held only.
struct PythonHooks {
  Forces forces;
  nb::object callback;                       // callback(): the Python side calls the user's f(sim)
  std::optional<std::uint64_t> every_steps;  // call it every N steps ...
  std::optional<double> every_time;          // ... or at every multiple of T of simulated time
  nb::object attach;                         // attach(native): hands the borrowed simulation to Python
  nb::object native;                         // that simulation, detached when the run ends
  std::atomic<bool>* stop = nullptr;
  std::optional<nb::python_error> raised;

  bool any() const { return !forces.empty() || !callback.is_none(); }
  // Runs f() (Python calls, with the GIL held) unless something was raised
  // already; an exception is kept (raised once the run returned) and stops the
  // run after this step. Returns f's result, None if it raised or was skipped.
  template <class F>
  nb::object guarded(F&& f) {
    if (raised) return nb::none();
    try {
      return std::forward<F>(f)();
    } catch (nb::python_error& e) {
      raised.emplace(std::move(e));
      *stop = true;
      return nb::none();
    }
  }
};

// The Python callback as an observer of the run: due every N steps (stateless)
// or at the times of an interval (IntervalSchedule, saved in checkpoints so a
// resumed run calls it where the uninterrupted one would have; adaptive steps
// land on those times).
template <class Real>
class PythonCallback final : public sim::Observer<Real> {
 public:
  PythonCallback(PythonHooks& hooks, double dt)
      : hooks_(hooks), schedule_(hooks.every_time.value_or(0), dt) {}
  std::string_view name() const override { return "python_callback"; }
  void on_step(Simulation<Real>& sim) override {
    const bool due = hooks_.every_steps ? sim.step_count() % *hooks_.every_steps == 0 : schedule_.due(sim.time());
    if (!due) return;
    if (!hooks_.every_steps) schedule_.acted(sim.time());
    nb::gil_scoped_acquire gil;
    nb::object r = hooks_.guarded([this] { return hooks_.callback(); });
    if (r.is(nb::bool_(false))) *hooks_.stop = true;
  }
  std::optional<double> next_time(const Simulation<Real>&) const override {
    return hooks_.every_steps ? std::nullopt : schedule_.next_time();
  }
  void save_state(NamedValues& out) const override {
    out.emplace_back("python_callback.next", static_cast<double>(schedule_.next_index()));
  }
  void load_state(const NamedValues& values) override {
    if (const auto k = find_value(values, "python_callback.next")) schedule_.set_next_index(static_cast<std::uint64_t>(*k));
  }

 private:
  PythonHooks& hooks_;
  sim::IntervalSchedule schedule_;
};

template <class Real>
sim::RunExtension<Real> python_extension(const scene::Scene& scene, PythonHooks& hooks) {
  return [&scene, &hooks](Simulation<Real>& sim) {
    nb::gil_scoped_acquire gil;
    hooks.native = borrow_simulation<Real>(sim, scene, hooks.forces);
    hooks.attach(hooks.native);
    std::vector<std::shared_ptr<sim::Observer<Real>>> observers;
    if (!hooks.callback.is_none()) observers.push_back(std::make_shared<PythonCallback<Real>>(hooks, scene.dt));
    return observers;
  };
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

nb::dict run(const scene::Scene& scene, const std::string& out_dir, bool resume, const RunArgs& a, nb::object progress,
             PythonHooks& hooks) {
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
  // output.surface: the fluid's mesh beside each frame, as `swirl run` writes it.
  if (scene.surface != scene::SurfaceFormat::None)
    options.on_frame = render::surface_frames(out_dir, render::fluid_surface_of(scene));
  hooks.stop = &stop;
  if (hooks.any()) {
    options.extend_float = python_extension<float>(scene, hooks);
    options.extend_double = python_extension<double>(scene, hooks);
  }
  auto on_progress = [&](const sim::RunProgress& p) {
    nb::gil_scoped_acquire gil;
    nb::object r = hooks.guarded([&]() -> nb::object {
      check_signals();
      if (progress.is_none()) return nb::none();
      nb::dict d;
      d["step"] = p.step;
      d["first_step"] = p.first_step;
      d["total_steps"] = p.total_steps;
      d["time"] = p.sim_time;
      d["wall_seconds"] = p.wall_seconds;
      return progress(d);
    });
    if (r.is(nb::bool_(false))) stop = true;
  };
  sim::RunSummary summary;
  try {
    nb::gil_scoped_release release;
    summary = sim::run_scene(scene, options, on_progress);
  } catch (...) {
    if (hooks.native.is_valid()) detach_simulation(hooks.native);
    throw;
  }
  if (hooks.native.is_valid()) detach_simulation(hooks.native);
  if (hooks.raised) throw std::move(*hooks.raised);
  return summary_dict(summary);
}

}  // namespace

void bind_run(nb::module_& m) {
  m.def(
      "run_scene",
      [](const PyScene& s, const std::string& out_dir, bool resume, std::optional<std::uint64_t> steps,
         std::optional<double> until, int threads, bool overwrite, std::optional<double> checkpoint_every,
         std::optional<std::uint64_t> checkpoint_every_steps, std::size_t checkpoint_keep, const std::string& on_blowup,
         nb::object progress, const Forces& forces, nb::object callback, std::optional<std::uint64_t> every_steps,
         std::optional<double> every_time, nb::object attach) {
        PythonHooks hooks{forces, std::move(callback), every_steps, every_time, std::move(attach), {}, nullptr, {}};
        return run(s.scene, out_dir, resume,
                   RunArgs{steps, until, threads, overwrite, checkpoint_every, checkpoint_every_steps, checkpoint_keep,
                           on_blowup},
                   progress, hooks);
      },
      nb::arg("scene"), nb::arg("out_dir"), nb::arg("resume"), nb::arg("steps").none(), nb::arg("until").none(),
      nb::arg("threads"), nb::arg("overwrite"), nb::arg("checkpoint_every").none(),
      nb::arg("checkpoint_every_steps").none(), nb::arg("checkpoint_keep"), nb::arg("on_blowup"),
      nb::arg("progress").none(), nb::arg("forces"), nb::arg("callback").none(), nb::arg("every_steps").none(),
      nb::arg("every_time").none(), nb::arg("attach").none());
}

}  // namespace swirl::python
