#include "swirl/view/replay.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string_view>
#include <variant>

#include <fmt/format.h>

#include "json.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/pvd.hpp"
#include "swirl/io/frame_names.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/vtp.hpp"
#include "swirl/render/fluid_surface.hpp"
#include "swirl/scene/load.hpp"

namespace swirl::view {
namespace fs = std::filesystem;

namespace {

// particles_NNNNNN: the frames `swirl run` writes.
bool is_frame_name(const fs::path& p, std::string_view extension) {
  return p.extension() == extension && io::frame_index(p, io::kParticleSeries).has_value();
}

std::vector<ReplayEntry> snapshot_frames(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && is_frame_name(e.path(), ".h5")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<ReplayEntry> out;
  for (auto& f : files) out.push_back({io::read_snapshot_layout(f).time, std::move(f)});  // the header only
  return out;
}

// The values of a .vtp array as floats (Float32/64 and the integer types).
std::optional<std::vector<float>> floats(const io::VtpArray& a) {
  auto convert = [&](auto tag) {
    using T = decltype(tag);
    const std::vector<T> v = a.values<T>();
    return std::vector<float>(v.begin(), v.end());
  };
  if (a.type == "Float32") return a.values<float>();
  if (a.type == "Float64") return convert(double{});
  if (a.type == "Int32") return convert(std::int32_t{});
  if (a.type == "UInt32") return convert(std::uint32_t{});
  if (a.type == "Int64") return convert(std::int64_t{});
  if (a.type == "UInt64") return convert(std::uint64_t{});
  return std::nullopt;
}

// Colourable fields from named arrays of 1 or 3 components (rows × components values).
struct NamedArray {
  std::string name;
  int components = 1;
  std::vector<float> values;
};

ReplayFrame frame_from(const fs::path& file, double time, const std::vector<float>& xyz, std::vector<NamedArray> arrays) {
  const std::size_t n = xyz.size() / 3;
  ReplayFrame f;
  f.time = time;
  f.x.resize(n), f.y.resize(n), f.z.resize(n);
  for (std::size_t i = 0; i < n; ++i) f.x[i] = xyz[3 * i], f.y[i] = xyz[3 * i + 1], f.z[i] = xyz[3 * i + 2];
  for (const auto& a : arrays)
    if (a.values.size() != n * std::size_t(a.components))
      throw io::IoError(fmt::format("{}: array '{}' has {} values for {} particles", file.string(), a.name,
                                    a.values.size(), n));
  auto magnitude = [n](const std::vector<float>& v) {
    std::vector<float> m(n);
    for (std::size_t i = 0; i < n; ++i)
      m[i] = float(std::sqrt(double(v[3 * i]) * v[3 * i] + double(v[3 * i + 1]) * v[3 * i + 1] +
                             double(v[3 * i + 2]) * v[3 * i + 2]));
    return m;
  };
  for (const auto& a : arrays)
    if (a.name == "velocity" && a.components == 3) f.fields.emplace_back("speed", magnitude(a.values));
  for (auto& a : arrays)
    if (a.components == 1 && a.name != "id") f.fields.emplace_back(a.name, std::move(a.values));
  for (const auto& a : arrays)
    if (a.components == 3 && a.name != "velocity") f.fields.emplace_back("|" + a.name + "|", magnitude(a.values));
  return f;
}

ReplayFrame read_vtp_frame(const fs::path& file) {
  const io::VtpFile vtp = io::read_vtp(file);
  const auto xyz = floats(vtp.points);
  if (!xyz || vtp.points.components != 3 || xyz->size() != 3 * vtp.num_points)
    throw io::IoError(fmt::format("{}: the points are not {} triples of numbers", file.string(), vtp.num_points));
  double time = 0;  // the frame's TimeValue (swirl writes Float64: read exactly, not through a float)
  if (const auto it = vtp.field_data.find("TimeValue"); it != vtp.field_data.end()) {
    if (it->second.type == "Float64") {
      if (const auto t = it->second.values<double>(); !t.empty()) time = t.front();
    } else if (const auto t = floats(it->second); t && !t->empty()) {
      time = double(t->front());
    }
  }
  std::vector<NamedArray> arrays;
  for (const auto& [name, a] : vtp.point_data) {
    if (a.components != 1 && a.components != 3) continue;
    if (auto v = floats(a)) arrays.push_back({name, a.components, std::move(*v)});
  }
  return frame_from(file, time, *xyz, std::move(arrays));
}

// Gadget's names of the built-in fields, as swirl names them in .vtp frames.
std::string swirl_name(const std::string& gadget) {
  static const std::map<std::string, std::string, std::less<>> names{{"Velocities", "velocity"},
                                                                     {"Accelerations", "acceleration"},
                                                                     {"Masses", "mass"},
                                                                     {"Density", "density"},
                                                                     {"Pressure", "pressure"},
                                                                     {"ParticleIDs", "id"}};
  const auto it = names.find(gadget);
  return it == names.end() ? gadget : it->second;
}

ReplayFrame read_snapshot_frame(const fs::path& file) {
  // read_snapshot checks shapes and finiteness and names the file.
  const io::SnapshotFile s = io::read_snapshot(file, io::frame_part_type(file));
  const auto& c = s.datasets.at("Coordinates");
  const std::vector<float> xyz(c.values.begin(), c.values.end());
  std::vector<NamedArray> arrays;
  for (const auto& [name, d] : s.datasets) {
    if (name == "Coordinates" || (d.columns != 1 && d.columns != 3)) continue;
    arrays.push_back({swirl_name(name), int(d.columns), std::vector<float>(d.values.begin(), d.values.end())});
  }
  return frame_from(file, s.info.time, xyz, std::move(arrays));
}

}  // namespace

RunFrames open_run(const fs::path& dir, ReplayFormat format) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw io::IoError(fmt::format("{}: not a run folder (no such directory)", dir.string()));
  RunFrames run;
  run.dir = dir;
  const fs::path pvd = dir / "particles.pvd";
  if (format != ReplayFormat::Hdf5 && fs::exists(pvd)) {
    for (const auto& e : io::read_pvd(pvd)) run.frames.push_back({e.time, dir / e.file});
  }
  if (run.frames.empty() && format != ReplayFormat::Vtp) run.frames = snapshot_frames(dir);
  if (run.frames.empty()) {
    const char* what = format == ReplayFormat::Vtp    ? "no particles.pvd listing .vtp frames"
                       : format == ReplayFormat::Hdf5 ? "no particles_NNNNNN.h5 snapshots"
                                                      : "no particles.pvd and no particles_NNNNNN.h5 snapshots";
    throw io::IoError(fmt::format("{}: not a run folder ({}); make one with: swirl run SCENE --out {}", dir.string(),
                                  what, dir.string()));
  }
  const fs::path scene_file = dir / "scene.toml";
  if (fs::exists(scene_file)) {
    try {
      // The scene loader's own read would block on a FIFO: io's checked read, then parse.
      run.scene = scene::parse_scene(io::read_regular_file(scene_file, io::kMaxSceneBytes), scene_file.string());
    } catch (const std::exception& e) {
      run.scene_note = e.what();
    }
  }
  return run;
}

namespace {

ReplayFrame read_one(const fs::path& file) {
  if (file.extension() == ".h5") return read_snapshot_frame(file);
  return read_vtp_frame(file);
}

// Appends `more`'s particles to `to`; a field the two do not share is dropped.
void append(ReplayFrame& to, ReplayFrame more) {
  const std::size_t n = to.x.size(), m = more.x.size();
  std::erase_if(to.fields, [&](auto& f) {
    const auto it = std::find_if(more.fields.begin(), more.fields.end(), [&](const auto& g) { return g.first == f.first; });
    if (it == more.fields.end() || f.second.size() != n || it->second.size() != m) return true;
    f.second.insert(f.second.end(), it->second.begin(), it->second.end());
    return false;
  });
  to.x.insert(to.x.end(), more.x.begin(), more.x.end());
  to.y.insert(to.y.end(), more.y.begin(), more.y.end());
  to.z.insert(to.z.end(), more.z.begin(), more.z.end());
}

}  // namespace

ReplayFrame read_replay_frame(const fs::path& file) {
  ReplayFrame f = read_one(file);
  if (const auto walls = io::boundary_frame_for(file)) append(f, read_one(*walls));
  return f;
}

namespace {

using Clock = std::chrono::steady_clock;

// The value of a frame's field by name, or null.
const std::vector<float>* field(const ReplayFrame& f, std::string_view name) {
  for (const auto& [n, values] : f.fields)
    if (n == name && values.size() == f.x.size()) return &values;
  return nullptr;
}

class ReplaySession {
 public:
  ReplaySession(const RunFrames& run, const ViewOptions& options)
      : run_(run),
        options_(options),
        playing_(!options.start_paused),
        server_(
            server_options(options), [this](const Control& c) { receive(c); },
            [this] {
              std::lock_guard lock(hello_mutex_);
              return hello_;
            },
            options.log) {}

  ViewResult run() {
    const auto t0 = Clock::now();
    current_ = read(0);  // the first frame, or an IoError naming it
    index_ = 0;
    fields_.clear();
    for (const auto& [name, values] : current_.fields) fields_.push_back(name);
    // The surface: a fluid's run whose frames have the masses (and, without
    // the scene's ρ0, the densities) that give each particle its volume.
    const scene::Scene* s = run_.scene ? &*run_.scene : nullptr;
    rest_density_ = s && s->sph ? s->sph->rest_density : 0.0;
    if (is_fluid() && field(current_, "mass") && (rest_density_ > 0 || field(current_, "density"))) {
      render::FluidSurface settings = s ? render::fluid_surface_of(*s) : render::FluidSurface{};
      settings.rest_density = rest_density_;
      settings.cell = options_.surface_cell;
      mesher_ = std::make_unique<Mesher>(
          settings, [this](std::shared_ptr<const std::string> m) { server_.publish_mesh(std::move(m)); }, options_.log);
    } else if (options_.surface) {
      throw std::invalid_argument(fmt::format(
          "swirl view: --surface draws a fluid's surface, and {} is {}", run_.dir.string(),
          is_fluid() ? "a fluid's run whose frames have no masses (or densities)" : "not a fluid's run"));
    }
    refresh_hello();
    const auto t_ready = Clock::now();
    server_.start();
    if (options_.on_listening) options_.on_listening(server_);
    publish();
    next_due_ = Clock::now() + period();
    while (!(options_.stop && options_.stop->load())) {
      apply_controls();
      // A viewer who turned the surface on, or came with it on (--surface): the frame shown again, with its surface.
      if (mesher_) {
        const std::size_t viewers = server_.surface_viewers();
        if (viewers > surface_viewers_) publish();
        surface_viewers_ = viewers;
      }
      if (playing_ && Clock::now() >= next_due_) {
        if (index_ + 1 < run_.frames.size()) {
          show(index_ + 1);
        } else {
          playing_ = false;  // the end: play again starts from the first frame
          refresh_hello();
          server_.announce(status());
        }
        next_due_ = std::max(next_due_ + period(), Clock::now());
      }
      report(false);
      std::unique_lock lock(control_mutex_);
      const auto until = playing_ ? std::min(next_due_, Clock::now() + std::chrono::milliseconds(50))
                                  : Clock::now() + std::chrono::milliseconds(50);
      wake_.wait_until(lock, until, [this] { return !controls_.empty(); });
    }
    ViewResult r;
    if (mesher_) {
      r.mesher = mesher_->stats();
      mesher_.reset();  // finishes the mesh being made (it publishes to the server, still running)
    }
    server_.stop();
    r.steps = shown_;
    r.refused = refused_;
    r.frames_read = frames_read_;
    r.read_seconds = read_seconds_;
    r.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    r.setup_seconds = std::chrono::duration<double>(t_ready - t0).count();
    r.server = server_.stats();
    return r;
  }

 private:
  Clock::duration period() const {
    const double rate = speed_ > 0 ? std::min(double(speed_), options_.fps) : options_.fps;
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate));
  }

  ReplayFrame read(std::size_t i) {
    const auto t = Clock::now();
    ReplayFrame f = read_replay_frame(run_.frames.at(i).file);
    read_seconds_ += std::chrono::duration<double>(Clock::now() - t).count();
    ++frames_read_;
    return f;
  }

  // Shows frame i: read, encoded and published; a frame that cannot be read pauses on the one shown.
  void show(std::size_t i) {
    if (i == index_) return publish();
    try {
      current_ = read(i);
      index_ = i;
    } catch (const std::exception& e) {
      playing_ = false;
      refresh_hello();
      const std::string line = fmt::format("swirl view: frame {} of the run cannot be read: {} (paused on frame {})", i,
                                           e.what(), index_);
      if (options_.log) options_.log(line);
      server_.announce(fmt::format(R"({{"type":"error","message":{}}})", json::string(line)));
      server_.announce(status());
      return;
    }
    publish();
  }

  void publish() {
    auto frame = std::make_shared<FrameData>();
    FrameData& f = *frame;
    f.step = index_;
    f.time = run_.frames[index_].time;
    f.x = current_.x, f.y = current_.y, f.z = current_.z;
    const std::size_t n = f.x.size();
    const scene::Scene* s = run_.scene ? &*run_.scene : nullptr;
    if (s && s->walls) {
      f.lo = {float(s->box.lo.x), float(s->box.lo.y), float(s->box.lo.z)};
      f.hi = {float(s->box.hi.x), float(s->box.hi.y), float(s->box.hi.z)};
    } else {  // open space: this frame's bounds
      f.lo = {INFINITY, INFINITY, INFINITY}, f.hi = {-INFINITY, -INFINITY, -INFINITY};
      const std::array<const std::vector<float>*, 3> axes{&f.x, &f.y, &f.z};
      for (std::size_t a = 0; a < 3; ++a)
        for (const float v : *axes[a])
          if (std::isfinite(v)) f.lo[a] = std::min(f.lo[a], v), f.hi[a] = std::max(f.hi[a], v);
      for (std::size_t a = 0; a < 3; ++a)
        if (!(f.lo[a] <= f.hi[a])) f.lo[a] = -1, f.hi[a] = 1;
    }
    // The field by its name: a later frame may lack it (then it is drawn uncoloured).
    if (colour_ < fields_.size())
      for (const auto& [name, values] : current_.fields)
        if (name == fields_[colour_] && values.size() == n) {
          f.colour = values;
          f.colour_field = std::uint16_t(colour_);
        }
    server_.publish(std::make_shared<const std::string>(encode_frame(f)));
    if (mesher_ && server_.surface_viewers() > 0) offer_mesh(std::move(frame));
    ++shown_;
    server_.announce(status());
  }

  // The frame's state for the mesher: each particle's volume m/ρ0 (m/ρ
  // without the scene's ρ0), 0 for a boundary particle (left out).
  void offer_mesh(std::shared_ptr<const FrameData> frame) {
    const std::vector<float>* mass = field(current_, "mass");
    const std::vector<float>* density = field(current_, "density");
    if (!mass || (rest_density_ <= 0 && !density)) return;  // a later frame without them: no surface for it
    const std::vector<float>* kind = field(current_, kKindField);
    MeshInput input;
    input.volumes.resize(mass->size());
    for (std::size_t i = 0; i < mass->size(); ++i) {
      const double rho = rest_density_ > 0 ? rest_density_ : double((*density)[i]);
      input.volumes[i] = (kind && is_boundary(std::int32_t((*kind)[i]))) || !(rho > 0) ? 0.0 : double((*mass)[i]) / rho;
    }
    input.frame = std::move(frame);
    mesher_->offer(std::move(input));
  }

  // A fluid's run: its scene says so, or (without one) its frames have a pressure.
  bool is_fluid() const {
    if (run_.scene) return run_.scene->sph.has_value();
    return std::find(fields_.begin(), fields_.end(), "pressure") != fields_.end();
  }

  void apply_controls() {
    std::deque<Control> todo;
    {
      std::lock_guard lock(control_mutex_);
      todo.swap(controls_);
    }
    std::size_t target = index_;
    bool recolour = false, changed = false;  // recolour: publish the frame shown again
    for (const Control& c : todo) {
      if (std::holds_alternative<control::Pause>(c)) {
        playing_ = false, changed = true;
      } else if (std::holds_alternative<control::Resume>(c)) {
        if (!playing_ && target + 1 >= run_.frames.size()) target = 0;  // at the end: from the start
        playing_ = true, changed = true;
        next_due_ = Clock::now() + period();
      } else if (std::holds_alternative<control::Step>(c)) {
        if (!playing_ && target + 1 < run_.frames.size()) ++target;
      } else if (std::holds_alternative<control::Reset>(c)) {
        target = 0;
      } else if (const auto* s = std::get_if<control::Speed>(&c)) {
        speed_ = s->steps_per_second;
      } else if (const auto* k = std::get_if<control::Colour>(&c)) {
        if (k->field < fields_.size()) colour_ = k->field, recolour = changed = true;
      } else if (const auto* seek = std::get_if<control::Seek>(&c)) {
        if (seek->frame < run_.frames.size()) target = seek->frame, recolour = true;  // answered by a frame, also when shown
        else refuse(fmt::format("seek to frame {}: the run has {} frames (0 to {})", seek->frame, run_.frames.size(),
                                run_.frames.size() - 1));
      } else if (std::holds_alternative<control::Push>(c)) {
        refuse("the push acts on a live run, not a replay");
      } else if (std::holds_alternative<control::Parameter>(c)) {
        refuse("live parameters act on a live run, not a replay");
      } else if (const auto* surface = std::get_if<control::Surface>(&c)) {
        // The server keeps who wants meshes (the session's loop acts on it).
        if (!mesher_ && surface->on)
          refuse("this run has no fluid surface (not a fluid's run, or its frames have no masses)");
      }
    }
    if (changed) refresh_hello();
    if (target != index_) {
      show(target);
      next_due_ = Clock::now() + period();
    } else if (recolour) {
      publish();
    } else if (changed) {
      server_.announce(status());
    }
  }

  // The 1st, 10th, 100th, ... refusal is logged (a page cannot flood the terminal); each is told to the viewers.
  void refuse(const std::string& why) {
    const std::uint64_t k = ++refused_;
    std::uint64_t p = 1;
    while (p < k) p *= 10;
    const std::string line = fmt::format("swirl view: refused a control from a viewer: {}", why);
    if (options_.log && p == k) options_.log(fmt::format("{} ({} so far)", line, k));
    server_.announce(fmt::format(R"({{"type":"refused","message":{}}})", json::string(line)));
  }

  void receive(const Control& c) {
    {
      std::lock_guard lock(control_mutex_);
      controls_.push_back(c);
    }
    wake_.notify_all();
  }

  void report(bool now) {
    if (!now && Clock::now() - last_status_ < std::chrono::milliseconds(500)) return;
    server_.announce(status());
    last_status_ = Clock::now();
  }

  std::string status() const {
    return fmt::format(
        R"({{"type":"status","mode":"replay","frame":{},"frames":{},"step":{},"time":{},"particles":{},"paused":{},"at_end":{},"speed":{},"surface":{}}})",
        index_, run_.frames.size(), index_, json::number(run_.frames[index_].time), current_.x.size(),
        json::boolean(!playing_), json::boolean(index_ + 1 == run_.frames.size()), json::number(speed_),
        mesher_json(mesher_.get()));
  }

  void refresh_hello() {
    std::string fields, times;
    for (const auto& f : fields_) {
      if (!fields.empty()) fields += ',';
      fields += json::string(f);
    }
    for (const auto& e : run_.frames) {
      if (!times.empty()) times += ',';
      times += json::number(e.time);
    }
    const scene::Scene* s = run_.scene ? &*run_.scene : nullptr;
    std::string box = "null";
    if (s && s->walls)
      box = fmt::format("[{},{},{},{},{},{}]", s->box.lo.x, s->box.lo.y, s->box.lo.z, s->box.hi.x, s->box.hi.y, s->box.hi.z);
    // Without a scene: a fluid has pressure, a gravity run a potential.
    auto has = [&](std::string_view name) { return std::find(fields_.begin(), fields_.end(), name) != fields_.end(); };
    const bool gravity = s ? s->nbody.has_value() : has("potential");
    const bool sph = is_fluid();
    std::string text = fmt::format(
        R"({{"type":"hello","mode":"replay","scene":{},"particles":{},"fields":[{}],"colour":{},"box":{},"gravity":{},"sph":{},"paused":{},"frames":{},"times":[{}],"parameters":[],"surface":{},"surface_on":{}}})",
        json::string(run_.dir.string()), current_.x.size(), fields, colour_, box, json::boolean(gravity),
        json::boolean(sph), json::boolean(!playing_), run_.frames.size(), times, json::boolean(mesher_ != nullptr),
        json::boolean(mesher_ && options_.surface));
    std::lock_guard lock(hello_mutex_);
    hello_ = std::move(text);
  }

  const RunFrames& run_;
  const ViewOptions& options_;
  ReplayFrame current_;
  std::size_t index_ = 0, colour_ = 0;
  std::vector<std::string> fields_;
  bool playing_ = true;
  float speed_ = 10;  // frames per second of playback
  Clock::time_point next_due_{}, last_status_{};
  std::uint64_t shown_ = 0, refused_ = 0, frames_read_ = 0;
  double read_seconds_ = 0;

  std::mutex control_mutex_;
  std::condition_variable wake_;
  std::deque<Control> controls_;
  std::mutex hello_mutex_;
  std::string hello_;
  double rest_density_ = 0;  // the scene's ρ0; 0: each particle's density gives its volume
  std::size_t surface_viewers_ = 0;  // as last seen by the session's loop

  LiveServer server_;
  std::unique_ptr<Mesher> mesher_;  // a fluid's run only; after server_, so that it stops first
};

}  // namespace

ViewResult replay_run(const RunFrames& run, const ViewOptions& options) {
  if (!(options.fps > 0)) throw std::invalid_argument("swirl view: fps must be > 0");
  if (run.frames.empty()) throw io::IoError(fmt::format("{}: no frames to replay", run.dir.string()));
  return ReplaySession(run, options).run();
}

}  // namespace swirl::view
