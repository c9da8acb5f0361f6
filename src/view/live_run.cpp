#include "swirl/view/live_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "json.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/render/fluid_surface.hpp"
#include "swirl/sim/build.hpp"
#include "swirl/sim/mechanics.hpp"
#include "swirl/view/parameters.hpp"
#include "swirl/view/push_force.hpp"

namespace swirl::view {
namespace {

using Clock = std::chrono::steady_clock;

// What can colour the particles: the speed, then every output scalar field
// (density, pressure, potential, ...) and integer field (a kind, a time bin).
struct Colouring {
  std::string name;
  enum Source { Speed, Real, Int } source = Speed;
  std::size_t index = 0;  // into fields() (the extra fields) or int fields
};

template <class Real>
std::vector<Colouring> colourings(const ParticleSet<Real>& p) {
  std::vector<Colouring> out{{"speed", Colouring::Speed, 0}};
  const auto real = p.fields();
  for (std::size_t k = 0; k < real.size(); ++k)
    if (real[k].components == 1 && !real[k].internal && real[k].name != "mass")
      out.push_back({std::string(real[k].name), Colouring::Real, k});
  const auto ints = p.int_fields();
  for (std::size_t k = 0; k < ints.size(); ++k)
    if (!ints[k].internal) out.push_back({std::string(ints[k].name), Colouring::Int, k});
  return out;
}

template <class Real>
class LiveSession {
 public:
  LiveSession(const scene::Scene& scene, const ViewOptions& options)
      : scene_(scene),
        options_(options),
        paused_(options.start_paused),
        server_(
            server_options(options), [this](const Control& c) { receive(c); }, [this] { return hello(); },
            options.log) {
    if (scene_.sph) {  // the surface is an SPH fluid's
      render::FluidSurface settings = render::fluid_surface_of(scene_);
      settings.cell = options.surface_cell;
      mesher_ = std::make_unique<Mesher>(
          settings, [this](std::shared_ptr<const std::string> m) { server_.publish_mesh(std::move(m)); }, options.log);
    }
  }
  // The server's thread calls hello(): it only reads the text the simulation's thread left.
  std::string hello() {
    std::lock_guard lock(hello_mutex_);
    return hello_;
  }

  ViewResult run() {
    const auto t0 = Clock::now();
    build();
    const auto t_built = Clock::now();
    server_.start();
    if (options_.on_listening) options_.on_listening(server_);
    std::thread encoder([this] { encode_loop(); });
    copy_frame(true);
    while (!(options_.stop && options_.stop->load())) {
      apply_controls();
      watch_surface_viewers();
      const bool step_once = (paused_ && !at_end_ && pending_steps_ > 0);
      if (step_once) --pending_steps_;
      if ((paused_ || at_end_) && !step_once) {
        {
          std::unique_lock lock(control_mutex_);
          wake_.wait_for(lock, std::chrono::milliseconds(50), [this] { return !controls_.empty(); });
        }
        if (recolour_.exchange(false)) copy_frame(true);
        report(false);
        continue;
      }
      if (speed_ > 0) std::this_thread::sleep_until(last_step_ + std::chrono::duration_cast<Clock::duration>(
                                                                    std::chrono::duration<double>(1.0 / speed_)));
      last_step_ = Clock::now();
      step();
      copy_frame(step_once || paused_ || at_end_);
      report(step_once);
    }
    {
      std::lock_guard lock(frame_mutex_);
      quit_ = true;
    }
    frame_cv_.notify_all();
    encoder.join();
    MesherStats meshes;
    if (mesher_) {
      meshes = mesher_->stats();
      mesher_.reset();  // finishes the mesh being made (it publishes to the server, still running)
    }
    server_.stop();
    ViewResult r;
    r.mesher = meshes;
    r.steps = steps_;
    r.resets = resets_;
    r.parameter_changes = changes_;
    r.refused = refused_;
    r.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    r.setup_seconds = std::chrono::duration<double>(t_built - t0).count();
    r.server = server_.stats();
    return r;
  }

 private:
  void build() {
    {
      std::lock_guard lock(push_mutex_);  // the server's thread may be handing the old force a push
      push_ = nullptr;
    }
    sim_ = std::make_unique<Simulation<Real>>(sim::build_simulation<Real>(scene_));
    if (parameters_.empty()) parameters_ = live_parameters(scene_, extent(sim_->particles()));
    // The gravity slider needs the uniform field, also where its g is (set to) zero.
    const bool offers_gravity = std::any_of(parameters_.begin(), parameters_.end(),
                                            [](const LiveParameter& p) { return p.id == control::ParameterId::Gravity; });
    if (offers_gravity && !sim_->template find_solver<UniformGravity<Real>>())
      sim_->add_solver(std::make_unique<UniformGravity<Real>>(scene_.gravity.template cast<Real>()));
    auto push = std::make_unique<PushForce<Real>>();
    {
      std::lock_guard lock(push_mutex_);
      push_ = push.get();
    }
    sim_->add_solver(std::move(push));
    sim_->start();
    fields_ = colourings(sim_->particles());
    at_end_ = false;
    refresh_hello();
  }

  // The largest side of the particles' bounds (the softening slider's scale).
  static double extent(const ParticleSet<Real>& p) {
    if (p.empty()) return 0;
    Vec3d lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec3d x{double(p.position.x[i]), double(p.position.y[i]), double(p.position.z[i])};
      lo = {std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
      hi = {std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
    }
    return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  }

  // A parameter's new value from a page: checked against its range, then set
  // in the solver between steps (here, on the simulation's thread), in the
  // scene a reset rebuilds, logged and told to every viewer.
  void set_parameter(const control::Parameter& c) {
    const auto it = std::find_if(parameters_.begin(), parameters_.end(),
                                 [&](const LiveParameter& p) { return p.id == c.id; });
    const Vec3d value{double(c.value.x), double(c.value.y), double(c.value.z)};
    std::string why = it == parameters_.end() ? fmt::format("this run has no parameter {}", int(c.id)) : refusal(*it, value);
    if (!why.empty()) return refuse(why);
    LiveParameter& p = *it;
    for (const auto& s : sim_->solvers()) {
      if (p.id == control::ParameterId::Viscosity) {
        if (auto* fluid = dynamic_cast<sph::SphFluid<Real>*>(s.get())) fluid->set_viscosity(value.x);
      } else if (p.id == control::ParameterId::Gravity) {
        if (auto* field = dynamic_cast<UniformGravity<Real>*>(s.get())) field->set_g(value.template cast<Real>());
      } else if (auto* self = dynamic_cast<gravity::GravityForce<Real>*>(s.get())) {
        self->set_softening(value.x);
      }
    }
    sim_->parameters_changed();
    const std::string line = fmt::format("swirl view: step {} (t = {:.6g}): {} {} -> {} (set by a viewer; the run "
                                         "from here is not the scene file's)",
                                         sim_->step_count(), sim_->time(), p.key, value_text(p, p.value),
                                         value_text(p, value));
    p.value = value;
    set_in_scene(scene_, p, value);
    ++changes_;
    if (options_.log) options_.log(line);
    server_.announce(fmt::format(R"({{"type":"parameter","key":{},"step":{},"time":{},"message":{}}})", json::string(p.key),
                                 sim_->step_count(), json::number(sim_->time()), json::string(line)));
    server_.announce(status());
    refresh_hello();
  }

  // A control the session cannot follow: told to the viewers, counted, and
  // logged (the 1st, 10th, 100th, ...: a page cannot flood the terminal).
  void refuse(const std::string& why) {
    const std::uint64_t k = ++refused_;
    std::uint64_t power = 1;
    while (power < k) power *= 10;
    const std::string line = fmt::format("swirl view: refused a control from a viewer: {}", why);
    if (options_.log && power == k) options_.log(fmt::format("{} ({} so far)", line, k));
    server_.announce(fmt::format(R"({{"type":"refused","message":{}}})", json::string(line)));
  }

  void step() {
    try {
      sim_->step(scene_.end_time ? std::optional<double>(*scene_.end_time) : std::nullopt);
      ++steps_;
    } catch (const SimulationError& e) {
      paused_ = true;
      refresh_hello();
      server_.announce(fmt::format(R"({{"type":"error","message":{}}})", json::string(e.what())));
      if (options_.log) options_.log(fmt::format("swirl view: {} (paused; reset starts over)", e.what()));
      return;
    }
    const bool ended = scene_.end_time ? sim_->time() >= *scene_.end_time * (1 - 1e-12)
                                       : scene_.steps && sim_->step_count() >= *scene_.steps;
    if (ended) {
      at_end_ = true;
      server_.announce(status());
    }
  }

  // A status message every half second, and at once after a single step (the page shows it).
  void report(bool now) {
    if (!now && Clock::now() - last_status_ < std::chrono::milliseconds(500)) return;
    server_.announce(status());
    last_status_ = Clock::now();
  }

  // Applies the controls received since the last call (single steps are
  // counted in pending_steps_ and taken one per loop, each with its frame).
  void apply_controls() {
    std::deque<Control> todo;
    {
      std::lock_guard lock(control_mutex_);
      todo.swap(controls_);
    }
    for (const Control& c : todo) {
      if (std::holds_alternative<control::Pause>(c)) paused_ = true, refresh_hello();
      else if (std::holds_alternative<control::Resume>(c)) paused_ = false, pending_steps_ = 0, refresh_hello();
      else if (std::holds_alternative<control::Step>(c)) pending_steps_ += paused_ ? 1 : 0;
      else if (std::holds_alternative<control::Reset>(c)) {
        build();
        ++resets_;
        pending_steps_ = 0;
        copy_frame(true);
        server_.announce(status());
      } else if (const auto* s = std::get_if<control::Speed>(&c)) {
        speed_ = s->steps_per_second;
      } else if (const auto* k = std::get_if<control::Colour>(&c)) {
        if (k->field < fields_.size()) colour_ = k->field, recolour_ = true, refresh_hello();
      } else if (const auto* v = std::get_if<control::Parameter>(&c)) {
        set_parameter(*v);
      } else if (const auto* surface = std::get_if<control::Surface>(&c)) {
        // The server keeps who wants meshes (watch_surface_viewers acts on it).
        if (!mesher_ && surface->on) refuse("the surface is an SPH fluid's, and this scene has no [sph]");
      } else if (std::holds_alternative<control::Seek>(c)) {
        refuse("seek is for a replay (swirl view RUN_DIR), not a live run");
      }
    }
  }

  // A viewer who turned the surface on, or came with it on (--surface), gets
  // the surface of the state shown now, also while paused: a new state copy,
  // which offers the mesher its state.
  void watch_surface_viewers() {
    if (!mesher_) return;
    const std::size_t viewers = server_.surface_viewers();
    if (viewers > surface_viewers_) recolour_ = true;
    surface_viewers_ = viewers;
  }

  // On the server's thread: a push goes straight to the force; the rest waits for the next step boundary.
  void receive(const Control& c) {
    if (const auto* p = std::get_if<control::Push>(&c)) {
      std::lock_guard lock(push_mutex_);
      if (push_) push_->set(*p);
      return;
    }
    {
      std::lock_guard lock(control_mutex_);
      controls_.push_back(c);
    }
    wake_.notify_all();
  }

  // The hello a new viewer receives, made on the simulation's thread whenever what it says changes.
  void refresh_hello() {
    std::string fields;
    for (const auto& f : fields_) {
      if (!fields.empty()) fields += ',';
      fields += json::string(f.name);
    }
    std::string box = "null";
    if (scene_.walls)
      box = fmt::format("[{},{},{},{},{},{}]", scene_.box.lo.x, scene_.box.lo.y, scene_.box.lo.z, scene_.box.hi.x,
                        scene_.box.hi.y, scene_.box.hi.z);
    std::string text = fmt::format(
        R"({{"type":"hello","mode":"live","scene":{},"particles":{},"fields":[{}],"colour":{},"box":{},"gravity":{},"sph":{},"paused":{},"parameters":{},"surface":{},"surface_on":{}}})",
        json::string(scene_.file), sim_ ? sim_->particles().size() : 0, fields, colour_.load(), box,
        scene_.nbody ? "true" : "false", scene_.sph ? "true" : "false", paused_ ? "true" : "false",
        parameters_json(parameters_), json::boolean(mesher_ != nullptr), json::boolean(mesher_ && options_.surface));
    std::lock_guard lock(hello_mutex_);
    hello_ = std::move(text);
  }

  // The parameters' values as the solvers hold them (what the statuses report).
  void read_back_parameters() {
    for (LiveParameter& p : parameters_) {
      if (p.id == control::ParameterId::Viscosity) {
        if (const auto* fluid = sim_->template find_solver<sph::SphFluid<Real>>()) p.value = {fluid->parameters().viscosity, 0, 0};
      } else if (p.id == control::ParameterId::Gravity) {
        if (const auto* field = sim_->template find_solver<UniformGravity<Real>>()) p.value = field->g().template cast<double>();
      } else if (const auto* self = sim_->template find_solver<gravity::GravityForce<Real>>()) {
        p.value = {self->settings().softening, 0, 0};
      }
    }
  }

  std::string status() {
    read_back_parameters();
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - status_clock_).count();
    const double rate = dt > 0 ? double(steps_ - status_steps_) / dt : 0;
    status_clock_ = now, status_steps_ = steps_;
    // The numbers of the run's diagnostics.csv (sim/mechanics.hpp), for the page's plots.
    const auto& p = sim_->particles();
    const std::size_t block_size = sim_->settings().block_size;
    const double kinetic = sim::mechanics(p, block_size).kinetic;
    const double potential = sim::potential_energy(*sim_, p, block_size);
    std::string diagnostics;
    for (const auto& [name, value] : sim::diagnostic_values(*sim_, p, block_size))
      diagnostics += fmt::format("{}{}:{}", diagnostics.empty() ? "" : ",", json::string(name), json::number(value));
    return fmt::format(
        R"({{"type":"status","mode":"live","step":{},"time":{},"steps_per_second":{},"paused":{},"at_end":{},"kinetic_energy":{},"potential_energy":{},"diagnostics":{{{}}},"parameters":{},"surface":{}}})",
        sim_->step_count(), json::number(sim_->time()), json::number(rate), paused_ ? "true" : "false",
        at_end_ ? "true" : "false", json::number(kinetic), json::number(potential), diagnostics,
        parameter_values_json(parameters_), mesher_json(mesher_.get()));
  }

  // Copies the state for the encoder when it is idle and a frame is due (or forced).
  void copy_frame(bool force) {
    const auto now = Clock::now();
    {
      std::lock_guard lock(frame_mutex_);
      if (encoder_busy_) {
        if (force) missed_ = true;
        return;
      }
      if (!force && now - last_frame_ < std::chrono::duration<double>(1.0 / options_.fps)) return;
    }
    const auto& p = sim_->particles();
    const std::size_t n = p.size();
    auto frame = std::make_shared<FrameData>();
    FrameData& f = *frame;
    f.step = sim_->step_count();
    f.time = sim_->time();
    f.x.resize(n), f.y.resize(n), f.z.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      f.x[i] = float(p.position.x[i]), f.y[i] = float(p.position.y[i]), f.z[i] = float(p.position.z[i]);
    if (scene_.walls) {
      f.lo = {float(scene_.box.lo.x), float(scene_.box.lo.y), float(scene_.box.lo.z)};
      f.hi = {float(scene_.box.hi.x), float(scene_.box.hi.y), float(scene_.box.hi.z)};
    } else {  // open space: this frame's bounds, finite positions only
      f.lo = {INFINITY, INFINITY, INFINITY}, f.hi = {-INFINITY, -INFINITY, -INFINITY};
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t a = 0; a < 3; ++a) {
          const float v = a == 0 ? f.x[i] : a == 1 ? f.y[i] : f.z[i];
          if (std::isfinite(v)) f.lo[a] = std::min(f.lo[a], v), f.hi[a] = std::max(f.hi[a], v);
        }
      for (std::size_t a = 0; a < 3; ++a)
        if (!(f.lo[a] <= f.hi[a])) f.lo[a] = -1, f.hi[a] = 1;
    }
    const Colouring& c = fields_.at(std::min<std::size_t>(colour_, fields_.size() - 1));
    f.colour_field = std::uint16_t(colour_);
    f.colour.resize(n);
    const auto real = p.fields();
    for (std::size_t i = 0; i < n; ++i) {
      switch (c.source) {
        case Colouring::Speed:
          f.colour[i] = float(std::sqrt(double(p.velocity.x[i]) * double(p.velocity.x[i]) +
                                        double(p.velocity.y[i]) * double(p.velocity.y[i]) +
                                        double(p.velocity.z[i]) * double(p.velocity.z[i])));
          break;
        case Colouring::Real: f.colour[i] = float(real[c.index].data[0][i]); break;
        case Colouring::Int: f.colour[i] = float(p.int_field(c.index)[i]); break;
      }
    }
    // The surface's state: this frame's positions and the fluid's volumes,
    // when some viewer wants a mesh and the mesher is free (or a forced
    // frame's state, which waits for the mesher).
    std::optional<MeshInput> mesh;
    if (mesher_ && server_.surface_viewers() > 0 && (force || !mesher_->busy())) {
      mesh.emplace();
      mesh->volumes.resize(n);
      const double rho0 = scene_.sph->rest_density;
      const std::size_t k = p.find_int_field(kKindField);
      const std::int32_t* kind = k == ParticleSet<Real>::npos ? nullptr : p.int_field(k).data();
      for (std::size_t i = 0; i < n; ++i)
        mesh->volumes[i] = kind && is_boundary(kind[i]) ? 0.0 : double(p.mass[i]) / rho0;
    }
    std::shared_ptr<const FrameData> shared = std::move(frame);
    if (mesh) {
      mesh->frame = shared;
      mesher_->offer(std::move(*mesh));
    }
    {
      std::lock_guard lock(frame_mutex_);
      pending_ = std::move(shared);
      encoder_busy_ = true;
      last_frame_ = now;
    }
    frame_cv_.notify_all();
  }

  void encode_loop() {
    for (;;) {
      std::shared_ptr<const FrameData> f;
      {
        std::unique_lock lock(frame_mutex_);
        frame_cv_.wait(lock, [this] { return quit_ || pending_; });
        if (quit_) return;
        f = std::move(pending_);
      }
      server_.publish(std::make_shared<const std::string>(encode_frame(*f)));
      bool again = false;
      {
        std::lock_guard lock(frame_mutex_);
        encoder_busy_ = false;
        again = std::exchange(missed_, false);
      }
      if (again) recolour_ = true;  // a forced frame was skipped while busy: the loop sends it
    }
  }

  scene::Scene scene_;  // the scene, with the live parameters' values changed so far (a reset rebuilds it)
  const ViewOptions& options_;
  std::unique_ptr<Simulation<Real>> sim_;
  std::vector<LiveParameter> parameters_;
  std::uint64_t changes_ = 0, refused_ = 0;
  std::mutex hello_mutex_;
  std::string hello_;
  std::mutex push_mutex_;  // push_: replaced on the simulation's thread (reset), used on the server's
  PushForce<Real>* push_ = nullptr;
  std::vector<Colouring> fields_;
  std::atomic<std::size_t> colour_{0};
  std::atomic<bool> recolour_{false};
  std::size_t surface_viewers_ = 0;  // as last seen by watch_surface_viewers
  bool paused_ = false, at_end_ = false;
  float speed_ = 0;
  std::uint64_t steps_ = 0, resets_ = 0, status_steps_ = 0, pending_steps_ = 0;
  Clock::time_point last_step_{}, status_clock_ = Clock::now(), last_status_{};

  std::mutex control_mutex_;
  std::condition_variable wake_;
  std::deque<Control> controls_;

  std::mutex frame_mutex_;
  std::condition_variable frame_cv_;
  std::shared_ptr<const FrameData> pending_;  // shared with the mesher, which may still read it
  bool encoder_busy_ = false, quit_ = false, missed_ = false;
  Clock::time_point last_frame_{};

  LiveServer server_;
  std::unique_ptr<Mesher> mesher_;  // SPH scenes only; after server_, so that it stops first
};

}  // namespace

ServerOptions server_options(const ViewOptions& options) {
  ServerOptions s = options.server;
  s.surface_on_connect = options.surface;
  return s;
}

ViewResult view_scene(const scene::Scene& scene, const ViewOptions& options) {
  if (!(options.fps > 0)) throw std::invalid_argument("swirl view: fps must be > 0");
  if (options.surface && !scene.sph)
    throw std::invalid_argument(fmt::format("swirl view: --surface draws an SPH fluid's surface, and {} has no [sph]",
                                            scene.file));
  // The live session steps the simulation itself and tells the page the count once.
  if (scene.has_inlets_or_outlets())
    throw std::invalid_argument(fmt::format("swirl view: {} has inlets or outlets, whose changing particle count the "
                                            "live view does not follow yet; run it with swirl run and view the run "
                                            "folder",
                                            scene.file));
  if (options.threads > 0) parallel::set_thread_count(options.threads);
  if (scene.precision == scene::Precision::Float) return LiveSession<float>(scene, options).run();
  return LiveSession<double>(scene, options).run();
}

}  // namespace swirl::view
