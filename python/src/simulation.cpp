// A Simulation<float|double> for Python: built by sim::build_simulation (as
// `swirl run` builds it), stepped with the GIL released and signals checked
// between steps, its fields handed out as numpy arrays on the C++ memory.
//
// Views: field() returns a numpy array whose data is the field's own
// AlignedVector storage and whose owner is the Python simulation object, so
// the simulation outlives the array. The storage itself does not: a reorder
// swaps every field with a scratch buffer (the old one is freed) and a resize
// reallocates. So the Python side (python/swirl/_views.py) wraps each array in
// a FieldArray that keeps the epoch, the count and the data pointer it was
// made at and compares them before every use (StaleViewError otherwise).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include <nanobind/stl/unique_ptr.h>

#include "bindings.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/io/csv.hpp"
#include "swirl/io/frame_names.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/scene/validate.hpp"
#include "swirl/sim/inlets_outlets.hpp"
#include "swirl/sim/mechanics.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sim/observer.hpp"

namespace swirl::python {
namespace {

// A force written in Python: a Solver whose add_acceleration() takes the GIL
// and calls fn(t) (python/swirl/_simulation.py wraps the user's f(sim, t)),
// which adds to the acceleration fields through fresh views: the particle
// order was brought up to date before the solvers run. Timed as the phase
// "forces.<name>" (its cost, in Simulation.phases()). Energy: unknown, so a
// run with one reports no relative energy error.
template <class Real>
class PythonForce final : public Solver<Real> {
 public:
  PythonForce(std::string name, nb::object fn) : name_(std::move(name)), phase_("forces." + name_), fn_(std::move(fn)) {}
  ~PythonForce() override {
    nb::gil_scoped_acquire gil;
    fn_.reset();
  }
  std::string_view name() const override { return name_; }
  void add_acceleration(ParticleSet<Real>&, const SolverContext<Real>& ctx) override {
    std::optional<ScopedPhase> phase;
    if (ctx.timers) phase.emplace(*ctx.timers, phase_);
    nb::gil_scoped_acquire gil;
    fn_(ctx.time);
  }
  bool conserves_energy() const override { return false; }

 private:
  std::string name_, phase_;
  nb::object fn_;
};

// Extra fields given with the particles: name, components (1 or 3), n·components doubles, particle by particle.
struct ExtraField {
  std::string name;
  int components = 1;
  std::vector<double> values;
};
using ExtraFields = std::vector<ExtraField>;
// Extra integer fields (1 component of std::int32_t), particle by particle.
struct ExtraIntField {
  std::string name;
  std::vector<std::int32_t> values;
};
using ExtraIntFields = std::vector<ExtraIntField>;

// What Python sees of a Simulation<Real>, whichever Real.
class AnySimulation {
 public:
  virtual ~AnySimulation() = default;
  virtual void start() = 0;
  // A run's simulation (not owned, not stepped from Python), and cutting it off when the run ends.
  virtual bool borrowed() const = 0;
  virtual void detach() = 0;
  virtual void step(std::optional<double> land_at) = 0;
  virtual double time() const = 0;
  virtual std::uint64_t steps() const = 0;
  virtual std::uint64_t epoch() const = 0;
  virtual std::size_t size() const = 0;
  virtual double last_dt() const = 0;
  virtual double proposed_dt() const = 0;
  virtual bool adaptive() const = 0;
  virtual double dt() const = 0;
  virtual std::string precision() const = 0;
  // The array of one component of a field (name, component) on the C++ memory.
  virtual nb::object field(nb::handle owner, const std::string& name, int component) = 0;
  virtual std::uintptr_t data_pointer(const std::string& name, int component) = 0;
  // Reads element i straight from the C++ storage (tests compare views with it).
  virtual double value(const std::string& name, int component, std::size_t i) = 0;
  // (name, components, kind "real" | "int" | "id", internal) for every field.
  virtual nb::list fields() = 0;
  virtual nb::dict diagnostics() = 0;
  // The current state as a picture's frame (positions, velocity, mass, density, pressure; time).
  virtual render::Frame frame() = 0;
  virtual const render::RunInfo& run_info() const = 0;
  virtual nb::dict metrics() = 0;
  virtual nb::dict phases() = 0;
  // The files written: the frame, then its boundary particles' file when the set has any.
  virtual std::vector<std::string> write_frame(const std::string& path, const std::string& format) = 0;
};

template <class Real>
class TypedSimulation final : public AnySimulation {
 public:
  TypedSimulation(const scene::Scene& scene, const Forces& forces, const ExtraFields& fields,
                  const ExtraIntFields& int_fields)
      : owned_(std::in_place, BuiltBy{[&] { return sim::build_simulation<Real>(scene); }}), sim_(&*owned_),
        block_size_(scene.block_size), walls_(scene.walls), restitution_(scene.restitution),
        run_info_(picture_info(scene)) {
    // Inlets and outlets change the count after every step, as in a run (the views notice: count and epoch).
    if (scene.has_inlets_or_outlets()) inlets_ = std::make_unique<sim::InletsAndOutlets<Real>>(scene);
    add_python_forces(live(), forces);
    // Before start(): storage order is still the order given (a list source), and the
    // first reorder carries the field along like every other.
    auto& p = live().particles();
    for (const auto& f : fields) {
      const std::size_t k = p.add_field(f.name, f.components);
      for (int c = 0; c < f.components; ++c)
        for (std::size_t i = 0; i < p.size(); ++i)
          p.extra(k, c)[i] = static_cast<Real>(f.values[i * static_cast<std::size_t>(f.components) + static_cast<std::size_t>(c)]);
    }
    for (const auto& f : int_fields) {
      const std::size_t k = p.add_int_field(f.name);
      std::copy(f.values.begin(), f.values.end(), p.int_field(k).begin());
    }
  }

  // A run's simulation (swirl.run's callback), not owned: it is the run's, and
  // detach() cuts this object off from it when the run ends.
  TypedSimulation(Simulation<Real>& borrowed, const scene::Scene& scene)
      : sim_(&borrowed), block_size_(scene.block_size), walls_(scene.walls), restitution_(scene.restitution),
        conservative_(false), run_info_(picture_info(scene)) {}

  // Python forces as solvers after the scene's own.
  static void add_python_forces(Simulation<Real>& sim, const Forces& forces) {
    for (const auto& [name, fn] : forces) sim.add_solver(std::make_unique<PythonForce<Real>>(name, fn));
  }

  bool borrowed() const override { return !owned_; }
  void detach() override { sim_ = nullptr; }

  // The initial forces; once, before anything else (the Python object exists by then, for the forces).
  void start() override {
    live().start();
    if (inlets_) inlets_->on_start(live(), false);
    conservative_ = std::all_of(live().solvers().begin(), live().solvers().end(),
                                [](const auto& s) { return s->conserves_energy(); }) &&
                    (!walls_ || restitution_ == 1);
    initial_energy_ = energies().total;
  }

  void step(std::optional<double> land_at) override {
    live().step(land_at);
    if (inlets_) inlets_->on_step(live());
  }
  double time() const override { return live().time(); }
  std::uint64_t steps() const override { return live().step_count(); }
  std::uint64_t epoch() const override { return live().epoch(); }
  std::size_t size() const override { return live().particles().size(); }
  double last_dt() const override { return live().last_dt(); }
  double proposed_dt() const override { return live().proposed_dt(); }
  bool adaptive() const override { return live().settings().adaptive; }
  double dt() const override { return live().settings().dt; }
  std::string precision() const override { return std::is_same_v<Real, float> ? "float" : "double"; }

  nb::object field(nb::handle owner, const std::string& name, int component) override {
    const Located where = locate(name, component);
    const std::size_t shape[1] = {size()};
    if (where.real) return nb::cast(nb::ndarray<nb::numpy, Real, nb::ndim<1>>(where.real, 1, shape, owner));
    if (where.integer)
      return nb::cast(nb::ndarray<nb::numpy, std::int32_t, nb::ndim<1>>(where.integer, 1, shape, owner));
    // Ids are the particles' identities: read-only.
    return nb::cast(nb::ndarray<nb::numpy, const std::uint64_t, nb::ndim<1>>(where.id, 1, shape, owner));
  }
  std::uintptr_t data_pointer(const std::string& name, int component) override {
    const Located where = locate(name, component);
    return where.real ? reinterpret_cast<std::uintptr_t>(where.real)
           : where.integer ? reinterpret_cast<std::uintptr_t>(where.integer)
                           : reinterpret_cast<std::uintptr_t>(where.id);
  }
  double value(const std::string& name, int component, std::size_t i) override {
    if (i >= size()) throw nb::index_error(fmt::format("particle index {} out of range (n = {})", i, size()).c_str());
    const Located where = locate(name, component);
    return where.real ? double(where.real[i]) : where.integer ? double(where.integer[i]) : double(where.id[i]);
  }
  nb::list fields() override {
    nb::list out;
    auto& p = live().particles();
    for (const auto& f : p.fields()) out.append(nb::make_tuple(std::string(f.name), f.components, "real", f.internal));
    for (const auto& f : p.int_fields()) out.append(nb::make_tuple(std::string(f.name), 1, "int", f.internal));
    out.append(nb::make_tuple("id", 1, "id", false));
    return out;
  }

  // The figures of one row of diagnostics.csv (sim/run.cpp's DiagnosticsLog):
  // energies, momentum, angular momentum about the origin, and every solver's and the stepper's own columns (sim/mechanics.hpp, as the log).
  nb::dict diagnostics() override {
    const Energies e = energies();
    nb::dict d;
    d["time"] = live().time();
    d["step"] = live().step_count();
    d["kinetic_energy"] = e.kinetic;
    d["potential_energy"] = e.potential;
    d["total_energy"] = e.total;
    if (conservative_)
      d["relative_energy_error"] = initial_energy_ != 0 ? (e.total - initial_energy_) / std::abs(initial_energy_) : 0.0;
    const char* axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) d[fmt::format("momentum_{}", axes[k]).c_str()] = e.momentum[static_cast<std::size_t>(k)];
    for (int k = 0; k < 3; ++k)
      d[fmt::format("angular_momentum_{}", axes[k]).c_str()] = e.angular[static_cast<std::size_t>(k)];
    for (const auto& [name, value] : sim::diagnostic_values(live(), live().particles(), block_size_)) d[name.c_str()] = value;
    return d;
  }
  nb::dict metrics() override {
    NamedValues values;
    for (const auto& s : live().solvers()) s->add_metrics(values);
    if (live().order().active()) values.emplace_back("sorts", double(live().order().sorts()));
    nb::dict d;
    for (const auto& [k, v] : values) d[k.c_str()] = v;
    return d;
  }
  nb::dict phases() override {
    nb::dict d;
    for (const auto& [k, v] : live().timers().phases()) d[k.c_str()] = v;
    return d;
  }
  render::Frame frame() override {
    const auto& p = live().particles();
    render::Frame f;
    f.file = "<simulation>";
    f.time = live().time();
    const std::size_t n = p.size();
    f.positions.resize(n);
    f.velocity.resize(n);
    f.mass.resize(n);
    f.density.resize(n);
    f.pressure.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      f.positions[i] = p.position.get(i).template cast<double>();
      f.velocity[i] = p.velocity.get(i).template cast<double>();
      f.mass[i] = p.mass[i];
      f.density[i] = p.density[i];
      f.pressure[i] = p.pressure[i];
    }
    return f;
  }
  const render::RunInfo& run_info() const override { return run_info_; }

  // The frame as the run's frame writer writes it (the same io:: writers, and
  // the same split: boundary particles in a file of their own beside it,
  // io::boundary_file_beside, which swirl render and the replay pair with it).
  std::vector<std::string> write_frame(const std::string& path, const std::string& format) override {
    if (format != "vtp" && format != "csv")
      throw nb::value_error(fmt::format("format '{}': give \"vtp\" or \"csv\"", format).c_str());
    const auto write = [&](const std::string& file, const ParticleSet<Real>& set) {
      if (format == "vtp") io::write_vtp(file, set, live().time());
      else io::write_csv(file, set, live().time());
    };
    const ParticleSet<Real>& p = live().particles();
    const KindSplit split = split_by_kind(p);
    if (split.boundary.empty()) {
      write(path, p);
      return {path};
    }
    const std::string boundary = io::boundary_file_beside(path).string();
    write(path, p.subset(split.rest));
    write(boundary, p.subset(split.boundary));
    return {path, boundary};
  }

 private:
  struct Located {
    Real* real = nullptr;
    std::int32_t* integer = nullptr;
    const std::uint64_t* id = nullptr;
  };
  Located locate(const std::string& name, int component) {
    auto& p = live().particles();
    if (name == "id") {
      if (component != 0) throw nb::index_error("field 'id' has one component");
      return {nullptr, nullptr, p.id.data()};
    }
    for (const auto& f : p.fields())
      if (f.name == name) {
        if (component < 0 || component >= f.components)
          throw nb::index_error(fmt::format("field '{}' has {} component(s), not component {}", name, f.components,
                                            component).c_str());
        return {f.data[static_cast<std::size_t>(component)], nullptr, nullptr};
      }
    for (const auto& f : p.int_fields())
      if (f.name == name) {
        if (component != 0) throw nb::index_error(fmt::format("field '{}' has one component", name).c_str());
        return {nullptr, f.data[0], nullptr};
      }
    std::string known;
    for (const auto& f : p.fields()) known += (known.empty() ? "" : ", ") + std::string(f.name);
    for (const auto& f : p.int_fields()) known += ", " + std::string(f.name);
    throw nb::key_error(fmt::format("no particle field '{}' (the fields: {}, id)", name, known).c_str());
  }

  struct Energies {
    double kinetic = 0, potential = 0, total = 0;
    std::array<double, 3> momentum{}, angular{};
  };
  // The log's sums (sim/mechanics.hpp): block order, boundary particles left out.
  Energies energies() const {
    const auto& p = live().particles();
    const sim::Mechanics m = sim::mechanics(p, block_size_);
    Energies e;
    e.kinetic = m.kinetic, e.momentum = m.momentum, e.angular = m.angular;
    e.potential = sim::potential_energy(live(), p, block_size_);
    e.total = e.kinetic + e.potential;
    return e;
  }

  // Constructs the owned simulation in place from a function's result (no move).
  template <class F>
  struct BuiltBy {
    F make;
    operator std::invoke_result_t<F>() { return make(); }  // NOLINT(google-explicit-constructor)
  };
  Simulation<Real>& live() const {
    if (sim_ == nullptr)
      throw std::runtime_error("this Simulation was a run's (swirl.run's callback) and the run has ended: it is gone "
                               "(keep copies of what you need: .copy(), sorted_by_id())");
    return *sim_;
  }

  static render::RunInfo picture_info(const scene::Scene& scene) {
    render::RunInfo info = render::run_info_of(scene);
    info.scene_name = std::filesystem::path(scene.file).stem().string();
    return info;
  }

  std::optional<Simulation<Real>> owned_;
  Simulation<Real>* sim_ = nullptr;
  std::size_t block_size_;
  bool walls_;
  double restitution_;
  bool conservative_ = true;
  double initial_energy_ = 0;
  render::RunInfo run_info_;
  std::unique_ptr<sim::InletsAndOutlets<Real>> inlets_;  // the scene's inlets and outlets, if any
};

std::unique_ptr<AnySimulation> make_simulation(const scene::Scene& scene, const Forces& forces,
                                               const ExtraFields& fields = {}, const ExtraIntFields& int_fields = {}) {
  if (scene.precision == scene::Precision::Float)
    return std::make_unique<TypedSimulation<float>>(scene, forces, fields, int_fields);
  return std::make_unique<TypedSimulation<double>>(scene, forces, fields, int_fields);
}

// The Python-facing object: the simulation and the stepping loops.
class PySimulation {
 public:
  explicit PySimulation(std::unique_ptr<AnySimulation> sim) : sim_(std::move(sim)) {}

  AnySimulation& sim() { return *sim_; }

  void start() {
    if (started_) return;
    sim_->start();
    started_ = true;
  }

  // n steps; signals (Ctrl-C) are checked after each one.
  void step(std::uint64_t n) {
    for (std::uint64_t k = 0; k < n; ++k) {
      one_step(std::nullopt);
      check_signals();
    }
  }

  // Steps until time `until` or `steps` more steps; calls callback() after
  // each step at which it is due (every_time: at the first step whose time is
  // >= k·every_time; every_steps: every that many steps); a callback that
  // returns False stops the run. Returns whether the callback stopped it.
  bool run(std::optional<double> until, std::optional<std::uint64_t> steps, std::optional<double> every_time,
           std::optional<std::uint64_t> every_steps, nb::object callback) {
    const std::uint64_t first = sim_->steps();
    std::uint64_t end_step = 0;
    if (steps) {
      end_step = first + *steps;
    } else if (!sim_->adaptive()) {
      // The step whose time is >= until (the rounding of Scene::total_steps).
      end_step = static_cast<std::uint64_t>(std::max(0.0, std::ceil(*until / sim_->dt() - 1e-9)));
    }
    sim::IntervalSchedule schedule(every_time.value_or(0), sim_->dt());
    if (schedule.enabled()) schedule.acted(sim_->time());
    auto running = [&] { return steps || !sim_->adaptive() ? sim_->steps() < end_step : sim_->time() < *until; };
    while (running()) {
      std::optional<double> land;
      if (sim_->adaptive()) {
        if (until) land = until;
        if (const auto t = schedule.next_time(); t && (!land || *t < *land)) land = t;
      }
      one_step(land);
      check_signals();
      bool due = every_steps && (sim_->steps() - first) % *every_steps == 0;
      if (schedule.due(sim_->time())) {
        schedule.acted(sim_->time());
        due = true;
      }
      if (due && !callback.is_none()) {
        nb::object result = callback();
        if (result.is(nb::bool_(false))) return true;
      }
    }
    return false;
  }

 private:
  // One step with the GIL released. A Python force that raised left the
  // state between a drift and a kick: the simulation refuses to go on.
  void one_step(std::optional<double> land) {
    if (!broken_.empty()) throw std::runtime_error(broken_);
    if (sim_->borrowed())
      throw std::logic_error("this Simulation is a run's (swirl.run's callback): the run steps it; a callback reads "
                             "and changes fields, and stops the run by returning False");
    if (!started_) throw std::logic_error("the simulation was not started (swirl.Simulation starts it)");
    try {
      nb::gil_scoped_release release;
      sim_->step(land);
    } catch (nb::python_error&) {
      broken_ = fmt::format("a Python force raised during step {} (t = {:.6g}), leaving the state inside that step; "
                            "this simulation cannot go on: build a new one",
                            sim_->steps() + 1, sim_->time());
      throw;
    }
  }

  std::unique_ptr<AnySimulation> sim_;
  bool started_ = false;
  std::string broken_;
};

// One row of a (n, 3) or (n,) array of doubles, checked finite.
void check_finite(const double* data, std::size_t n, std::size_t columns, const char* what) {
  for (std::size_t i = 0; i < n * columns; ++i)
    if (!std::isfinite(data[i]))
      throw nb::value_error(columns == 1 ? fmt::format("{}[{}] is {}, not a finite number", what, i, data[i]).c_str()
                                         : fmt::format("{}[{}, {}] is {}, not a finite number", what, i / columns,
                                                       i % columns, data[i]).c_str());
}

using Rows = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Column = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using AnyArray = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
using IntColumn = nb::ndarray<const std::int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

// The scene's physics with these particles instead of its [[particles]]:
// one list source, validated as a scene file's list is.
std::unique_ptr<AnySimulation> from_arrays(const PyScene& base, Rows positions, std::optional<Rows> velocities,
                                           Column masses, const Forces& forces,
                                           const std::vector<std::pair<std::string, AnyArray>>& named,
                                           const std::vector<std::pair<std::string, IntColumn>>& named_int) {
  const std::size_t n = positions.shape(0);
  if (positions.shape(1) != 3) throw nb::value_error("positions must have shape (n, 3)");
  if (velocities && (velocities->shape(0) != n || velocities->shape(1) != 3))
    throw nb::value_error(fmt::format("velocities must have shape ({}, 3), like positions", n).c_str());
  if (masses.shape(0) != n) throw nb::value_error(fmt::format("masses must have shape ({},), one per position", n).c_str());
  check_finite(positions.data(), n, 3, "positions");
  if (velocities) check_finite(velocities->data(), n, 3, "velocities");
  check_finite(masses.data(), n, 1, "masses");
  for (std::size_t i = 0; i < n; ++i)
    if (!(masses.data()[i] > 0)) throw nb::value_error(fmt::format("masses[{}] is {}: a mass must be > 0", i, masses.data()[i]).c_str());
  ExtraFields fields;
  for (const auto& [name, a] : named) {
    const bool vector = a.ndim() == 2 && a.shape(1) == 3;
    if (!((a.ndim() == 1 || vector) && a.shape(0) == n))
      throw nb::value_error(fmt::format("field '{}' must have shape ({},) or ({}, 3)", name, n, n).c_str());
    const std::size_t components = vector ? 3 : 1;
    check_finite(a.data(), n, components, name.c_str());
    fields.push_back({name, static_cast<int>(components), std::vector<double>(a.data(), a.data() + n * components)});
  }
  ExtraIntFields int_fields;
  for (const auto& [name, a] : named_int) {
    if (a.shape(0) != n) throw nb::value_error(fmt::format("field '{}' must have shape ({},)", name, n).c_str());
    int_fields.push_back({name, std::vector<std::int32_t>(a.data(), a.data() + n)});
  }
  scene::Scene s = base.scene;
  scene::ListSource list;
  list.positions.resize(n);
  list.masses.assign(masses.data(), masses.data() + n);
  for (std::size_t i = 0; i < n; ++i)
    list.positions[i] = {positions.data()[3 * i], positions.data()[3 * i + 1], positions.data()[3 * i + 2]};
  if (velocities) {
    list.velocities.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      list.velocities[i] = {velocities->data()[3 * i], velocities->data()[3 * i + 1], velocities->data()[3 * i + 2]};
  }
  s.sources = {std::move(list)};
  s.random_box.reset();
  s.toml.clear();  // the file's particles are not these
  s.file = (base.scene.file.empty() ? std::string("scene") : base.scene.file) + " (particles from arrays)";
  scene::validate(s);
  nb::gil_scoped_release release;
  return make_simulation(s, forces, fields, int_fields);
}

}  // namespace

template <class Real>
nb::object borrow_simulation(Simulation<Real>& sim, const scene::Scene& scene, const Forces& forces) {
  TypedSimulation<Real>::add_python_forces(sim, forces);
  return nb::cast(new PySimulation(std::make_unique<TypedSimulation<Real>>(sim, scene)), nb::rv_policy::take_ownership);
}
template nb::object borrow_simulation<float>(Simulation<float>&, const scene::Scene&, const Forces&);
template nb::object borrow_simulation<double>(Simulation<double>&, const scene::Scene&, const Forces&);

void detach_simulation(nb::handle native) { nb::cast<PySimulation&>(native).sim().detach(); }
render::Frame simulation_frame(nb::handle native) { return nb::cast<PySimulation&>(native).sim().frame(); }
render::RunInfo simulation_run_info(nb::handle native) { return nb::cast<PySimulation&>(native).sim().run_info(); }

void bind_simulation(nb::module_& m) {
  nb::class_<PySimulation>(m, "Simulation")
      .def("__init__",
           [](PySimulation* self, const PyScene& s, const Forces& forces) {
             std::unique_ptr<AnySimulation> sim;
             {
               nb::gil_scoped_release release;
               sim = make_simulation(s.scene, forces);
             }
             new (self) PySimulation(std::move(sim));
           },
           nb::arg("scene"), nb::arg("forces"))
      .def_static(
          "from_arrays",
          [](const PyScene& s, Rows positions, std::optional<Rows> velocities, Column masses, const Forces& forces,
             const std::vector<std::pair<std::string, AnyArray>>& fields,
             const std::vector<std::pair<std::string, IntColumn>>& int_fields) {
            return new PySimulation(from_arrays(s, positions, velocities, masses, forces, fields, int_fields));
          },
          nb::arg("scene"), nb::arg("positions").noconvert(), nb::arg("velocities").noconvert().none(),
          nb::arg("masses").noconvert(), nb::arg("forces"), nb::arg("fields"), nb::arg("int_fields"),
          nb::rv_policy::take_ownership)
      .def("start",
           [](PySimulation& s) {
             nb::gil_scoped_release release;
             s.start();
           })
      .def("step", &PySimulation::step, nb::arg("n"))
      .def("run", &PySimulation::run, nb::arg("until").none(), nb::arg("steps").none(), nb::arg("every_time").none(),
           nb::arg("every_steps").none(), nb::arg("callback").none())
      .def_prop_ro("time", [](PySimulation& s) { return s.sim().time(); })
      .def_prop_ro("steps", [](PySimulation& s) { return s.sim().steps(); })
      .def_prop_ro("epoch", [](PySimulation& s) { return s.sim().epoch(); })
      .def_prop_ro("count", [](PySimulation& s) { return s.sim().size(); })
      .def_prop_ro("last_dt", [](PySimulation& s) { return s.sim().last_dt(); })
      .def_prop_ro("proposed_dt", [](PySimulation& s) { return s.sim().proposed_dt(); })
      .def_prop_ro("precision", [](PySimulation& s) { return s.sim().precision(); })
      .def(
          "field",
          [](nb::handle self, const std::string& name, int component) {
            return nb::cast<PySimulation&>(self).sim().field(self, name, component);
          },
          nb::arg("name"), nb::arg("component"))
      .def("data_pointer", [](PySimulation& s, const std::string& name, int c) { return s.sim().data_pointer(name, c); })
      .def("value", [](PySimulation& s, const std::string& name, int c, std::size_t i) { return s.sim().value(name, c, i); })
      .def("fields", [](PySimulation& s) { return s.sim().fields(); })
      .def("diagnostics", [](PySimulation& s) { return s.sim().diagnostics(); })
      .def("metrics", [](PySimulation& s) { return s.sim().metrics(); })
      .def("phases", [](PySimulation& s) { return s.sim().phases(); })
      .def("write_frame", [](PySimulation& s, const std::string& path, const std::string& format) {
        nb::gil_scoped_release release;
        return s.sim().write_frame(path, format);
      });
}

}  // namespace swirl::python
