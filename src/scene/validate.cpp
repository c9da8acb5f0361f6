#include "swirl/scene/validate.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "messages.hpp"
#include "sources.hpp"
#include "swirl/scene/fluid_fill.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/keys.hpp"
#include "swirl/scene/mesh_sampling.hpp"

namespace swirl::scene {
namespace {

std::string count_text(std::uint64_t n) { return n == detail::kSaturated ? "over 1.8e19" : std::to_string(n); }

class Checker {
 public:
  explicit Checker(const Scene& s) : s_(s), file_(s.file.empty() ? std::string("scene") : s.file) {}

  [[noreturn]] void fail(std::string_view where, std::string_view reason) const { detail::fail(file_, where, reason); }

  void keys() const {
    // The format first: a newer scene's other keys may mean something else.
    if (const std::string problem = detail::format_version_problem(s_.format_version); !problem.empty())
      fail("format", problem);
    for (const auto& spec : scene_keys())
      if (const auto value = spec.get(s_)) detail::check_value(spec, *value, file_, spec.key);
  }

  void time() const {
    if (s_.end_time && s_.steps) fail("simulation.steps", "cannot be given together with simulation.end_time; give one of them");
    if (!s_.end_time && !s_.steps) fail("simulation.end_time", "missing required key (give end_time or simulation.steps)");
    // total_steps() converts end_time / dt to an integer; it must fit.
    if (s_.end_time && !s_.adaptive_dt && !(*s_.end_time / s_.dt <= 0x1p53))
      fail("simulation.end_time", fmt::format("needs {:.3g} steps of dt = {}, more than the limit of 2^53",
                                              *s_.end_time / s_.dt, s_.dt));
    if (s_.adaptive_dt && !(s_.dt_min < s_.dt))
      fail("simulation.dt_min", fmt::format("must be smaller than simulation.dt_max = {}, got {}", s_.dt, s_.dt_min));
    if (s_.time_steps == TimeSteps::Block) {
      // The bins are powers of two below one fixed step, by the gravity condition per particle.
      if (s_.adaptive_dt)
        fail("simulation.time_steps", "\"block\" needs a fixed simulation.dt (the largest step, bin 0), not \"adaptive\"");
      if (!s_.nbody || !(s_.nbody->softening > 0))
        fail("simulation.time_steps",
             "\"block\" needs [nbody] with nbody.softening > 0: a particle's bin comes from eta*sqrt(softening/|a|)");
      if (s_.walls)
        fail("simulation.time_steps", "\"block\" needs open space (no [box]): the walls reflect on whole steps");
    }
  }

  // G is a key only with [nbody] (keys() checked it there), but a Scene built
  // in code carries one anyway; whoever uses it may rely on G > 0.
  void units() const {
    if (!(s_.gravitational_constant > 0) || !std::isfinite(s_.gravitational_constant))
      fail("nbody.G", fmt::format("must be finite and > 0, got {}", s_.gravitational_constant));
  }

  void box() const {
    if (s_.walls) extent(s_.box, "box");
  }

  // The paper's schemes walk the paper's tree; only `global` can take the
  // linear one, and only the linear tree has multipoles and Barnes' rule.
  void nbody() const {
    if (!s_.nbody) return;
    const auto& g = *s_.nbody;
    // The FMM stands on the linear octree of the global scheme; the paper's schemes and tree are Barnes–Hut's.
    if (g.method == gravity::Method::Fmm && g.scheme != gravity::Scheme::Global)
      fail("nbody.scheme", fmt::format("\"{}\" is a Barnes-Hut scheme; method \"fmm\" needs scheme = \"global\"",
                                       gravity::to_string(g.scheme)));
    if (g.method == gravity::Method::Fmm && g.tree != gravity::Tree::Linear)
      fail("nbody.tree", "method \"fmm\" walks the linear octree: needs tree = \"linear\"");
    if (g.tree == gravity::Tree::Linear && g.scheme != gravity::Scheme::Global)
      fail("nbody.tree", fmt::format("\"linear\" needs nbody.scheme = \"global\" (the paper's scheme \"{}\" walks the "
                                     "paper's tree)",
                                     gravity::to_string(g.scheme)));
    if (g.tree == gravity::Tree::Linear) return;
    if (g.multipole != gravity::Multipole::Monopole)
      fail("nbody.multipole", "the paper's tree is monopole only (use tree = \"linear\" with scheme = \"global\")");
    if (g.criterion != gravity::Criterion::Paper)
      fail("nbody.opening_criterion",
           "the paper's tree uses the paper's rule only (use tree = \"linear\" with scheme = \"global\")");
    if (g.walk != gravity::Walk::Particle)
      fail("nbody.walk", "the paper's tree walks per particle only (use tree = \"linear\" with scheme = \"global\")");
  }

  void sph() const {
    if (!s_.sph) return;
    const sph::SphParameters& f = *s_.sph;
    if (f.method == sph::SphMethod::Dfsph) {
      if (f.neighbour_search != sph::NeighbourSearch::Grid)
        fail("sph.neighbour_search", "\"dfsph\" runs its solves on the sorted grid only; use \"grid\"");
      if (f.gradient_correction)
        fail("sph.gradient_correction", "corrects the thesis's pressure force, which \"dfsph\" does not use");
      if (s_.time_steps == TimeSteps::Block)
        fail("simulation.time_steps", "\"block\" cannot be combined with sph.method = \"dfsph\"");
    } else {
      if (f.kernel != sph::SphKernel::Thesis)
        fail("sph.kernel", fmt::format("\"{}\" needs sph.method = \"dfsph\" (the thesis's solver runs its own kernels)",
                                       enum_name<sph::SphKernel>(sph::kSphKernelNames, f.kernel)));
      for (const auto& [key, value] : {std::pair{"sph.xsph", f.xsph}, std::pair{"sph.surface_tension", f.surface_tension},
                                       std::pair{"sph.adhesion", f.adhesion}})
        if (value > 0)
          fail(key, fmt::format("{:g} needs sph.method = \"dfsph\" (the thesis's solver has no such term yet)", value));
    }
    if (f.adhesion > 0 && !s_.has_boundary_particles())
      fail("sph.adhesion", fmt::format("{:g} acts between the fluid and boundary particles, and the scene has none "
                                       "(box.walls = \"particles\" or an obstacle)",
                                       f.adhesion));
    const double keys = dense_cell_table_keys(s_);
    if (keys > 0x1p31)
      fail("sph.grid.table",
           fmt::format("a dense cell table over the box with cells of h + skin = {:g} would need {:.3g} entries, more "
                       "than 2^31; use \"auto\" or \"hashed\", or a larger smoothing length",
                       s_.sph->smoothing_length + s_.sph->grid_skin, keys));
  }

  // Boundary particles (walls or obstacles) are the fluid's: [sph] with the grid search.
  void boundary() const {
    const bool walls = s_.walls && s_.wall_kind == Walls::Particles;
    if (!s_.has_boundary_particles()) return;
    std::string where = "box.walls";
    for (std::size_t i = 0; i < s_.sources.size() && !walls; ++i)
      if (std::holds_alternative<ObstacleSource>(s_.sources[i])) {
        where = fmt::format("particles[{}].kind", i);
        break;
      }
    if (!s_.sph) fail(where, "boundary particles are the fluid's: they need an [sph] section");
    if (s_.sph->neighbour_search != sph::NeighbourSearch::Grid)
      fail("sph.neighbour_search", fmt::format("boundary particles ({}) need the grid search; use \"grid\"", where));
    if (walls && !(s_.wall_spacing > 0))
      fail("box.walls", fmt::format("\"particles\" needs the walls' spacing (the first fluid_block's), got {}",
                                    s_.wall_spacing));
  }

  void output() const {
    if (s_.surface == SurfaceFormat::None) return;
    if (!s_.sph)
      fail("output.surface", "the surface is the fluid's: it needs an [sph] section, and this scene has no fluid "
                             "(remove output.surface, or draw the particles with swirl render)");
    const auto& f = s_.formats;
    if (std::find(f.begin(), f.end(), OutputFormat::Vtp) == f.end() &&
        std::find(f.begin(), f.end(), OutputFormat::Hdf5) == f.end())
      fail("output.surface", "is made from the frames: output.format must include \"vtp\" or \"hdf5\"");
  }

  void sources() const {
    if (s_.sources.empty()) fail("particles", "no particles: the scene needs at least one [[particles]] source");
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < s_.sources.size(); ++i) {
      const ParticleSource& source = s_.sources[i];
      const std::string where = fmt::format("particles[{}]", i);
      if (const auto* m = std::get_if<StellarSource>(&source);
          m && enum_name<StellarSource::Model>(kStellarModelNames, m->model).empty())
        fail(fmt::format("{}.kind", where), "is not a valid stellar model");
      for (const auto& spec : kind_of(source).keys)
        if (const auto value = spec.get(source))
          detail::check_value(spec, *value, file_, fmt::format("{}.{}", where, spec.key));
      if (const auto* l = std::get_if<LatticeSource>(&source)) lattice(*l, where);
      else if (const auto* r = std::get_if<RandomSource>(&source)) region(r->region, where);
      else if (const auto* list = std::get_if<ListSource>(&source)) listed(*list, where);
      else if (const auto* snapshot = std::get_if<SnapshotSource>(&source)) snapshot_file(*snapshot, where);
      else if (const auto* obstacle = std::get_if<ObstacleSource>(&source)) {
        obstacle_shape(*obstacle, where);
        if (obstacle->motion) motion(*obstacle, where);
      } else if (const auto* f = std::get_if<FluidFillSource>(&source)) fill(*f, where);
      else stellar(std::get<StellarSource>(source), where);
      const std::uint64_t n = detail::source_count(source);
      if (n > detail::kMaxParticles)
        fail(where, fmt::format("makes {} particles, more than the limit of {} (2^31); is the spacing too small?",
                                count_text(n), detail::kMaxParticles));
      total = detail::add_sat(total, n);
    }
    if (total == 0) fail("particles", "no particles: the scene needs at least one [[particles]] source");
    total = detail::add_sat(total, detail::wall_count(s_));
    if (total > detail::kMaxParticles)
      fail("particles", fmt::format("the sources make {} particles in total, more than the limit of {} (2^31)",
                                    count_text(total), detail::kMaxParticles));
  }

  // [[probes]] and output.obstacle_forces (docs/sph.md, Probes): the fluid's,
  // inside the box, lines vertical, names usable as CSV column prefixes and
  // unique among the probes and the obstacles (whose default names count too).
  // [[inlets]] and [[outlets]] (docs/sph.md, Inlets and outlets).
  void inlets_and_outlets() const {
    for (std::size_t i = 0; i < s_.inlets.size(); ++i) {
      const Inlet& inlet = s_.inlets[i];
      const std::string where = fmt::format("inlets[{}]", i);
      const auto key = [&](std::string_view k) { return fmt::format("{}.{}", where, k); };
      for (const auto& spec : inlet_keys())
        if (const auto value = spec.get(inlet)) detail::check_value(spec, *value, file_, key(spec.key));
      if (!s_.sph) fail(where, "an inlet emits SPH fluid: the scene needs an [sph] section");
      if (s_.time_steps == TimeSteps::Block)
        fail(where, "an inlet needs simulation.time_steps = \"global\" (new particles have no time bin)");
      inside(inlet.center, key("center"));
      if (!(norm(inlet.direction) > 0)) fail(key("direction"), "must not be zero");
      if (inlet.stop && !(*inlet.stop > inlet.start))
        fail(key("stop"), fmt::format("must be greater than {} = {}, got {}", key("start"), inlet.start, *inlet.stop));
      if (!(inlet.mass > 0) || !std::isfinite(inlet.mass))
        fail(where, fmt::format("its particles' mass is {} (load_scene sets it from [sph]; a Scene built in code "
                                "must set Inlet::mass)",
                                inlet.mass));
      if (inlet.radius / inlet.spacing > 2048)
        fail(key("radius"), fmt::format("{} is over 2048 spacings ({}): a layer would hold over 13 million particles",
                                        inlet.radius, inlet.spacing));
    }
    for (std::size_t i = 0; i < s_.outlets.size(); ++i) {
      const Outlet& outlet = s_.outlets[i];
      const std::string where = fmt::format("outlets[{}]", i);
      for (const auto& spec : outlet_keys())
        if (const auto value = spec.get(outlet)) detail::check_value(spec, *value, file_, fmt::format("{}.{}", where, spec.key));
      if (s_.time_steps == TimeSteps::Block)
        fail(where, "an outlet needs simulation.time_steps = \"global\" (a changing count has no time bins)");
      for (int a = 0; a < 3; ++a)
        if (!(outlet.region.hi[a] > outlet.region.lo[a]))
          fail(fmt::format("{}.max", where), fmt::format("must be greater than {}.min on every axis; along {}: {} ≤ {}",
                                                         where, "xyz"[a], outlet.region.hi[a], outlet.region.lo[a]));
    }
  }

  void probes() const {
    if (s_.obstacle_forces && !s_.has_boundary_particles())
      fail("output.obstacle_forces", "the scene has no boundary particles to measure (no obstacle_* source, and "
                                     "box.walls is not \"particles\")");
    std::vector<std::pair<std::string, std::string>> names;  // name, where it was given
    const auto add_name = [&](const std::string& name, const std::string& where) {
      if (name.empty() || name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") !=
                              std::string::npos)
        fail(where, fmt::format("'{}' is not a usable name: letters, digits and _ only (it starts columns of probes.csv)",
                                name));
      for (const auto& [other, at] : names)
        if (other == name) fail(where, fmt::format("the name '{}' is already taken by {}", name, at));
      names.emplace_back(name, where);
    };
    if (s_.obstacle_forces) {
      std::size_t k = 0;
      for (std::size_t i = 0; i < s_.sources.size(); ++i)
        if (const auto* o = std::get_if<ObstacleSource>(&s_.sources[i])) {
          ++k;
          add_name(o->name.empty() ? fmt::format("obstacle{}", k) : o->name,
                   fmt::format("particles[{}].name{}", i, o->name.empty() ? " (its default)" : ""));
        }
      if (s_.walls && s_.wall_kind == Walls::Particles) add_name("walls", "box.walls (the walls' name)");
    }
    for (std::size_t i = 0; i < s_.probes.size(); ++i) {
      const Probe& probe = s_.probes[i];
      const std::string where = fmt::format("probes[{}]", i);
      for (const auto& spec : probe_keys())
        if (const auto value = spec.get(probe)) detail::check_value(spec, *value, file_, fmt::format("{}.{}", where, spec.key));
      if (!s_.sph) fail(fmt::format("{}.name", where), "a probe samples the SPH fluid: the scene needs an [sph] section");
      add_name(probe.name, fmt::format("{}.name", where));
      if (probe.point.has_value() == !probe.line.empty())
        fail(where, "give exactly one of point and line");
      if (probe.point) {
        inside(*probe.point, fmt::format("{}.point", where));
        continue;
      }
      if (probe.line.size() != 2) fail(fmt::format("{}.line", where), "expected two points, the lower and the upper end");
      const Vec3d& a = probe.line[0];
      const Vec3d& b = probe.line[1];
      if (a.x != b.x || a.y != b.y)
        fail(fmt::format("{}.line", where),
             fmt::format("must be vertical (a water-height gauge): its ends {} and {} differ in x or y",
                         detail::vec_text(a), detail::vec_text(b)));
      if (!(a.z < b.z))
        fail(fmt::format("{}.line", where),
             fmt::format("the first point is the lower end: z0 = {} must be below z1 = {}", a.z, b.z));
      inside(a, fmt::format("{}.line[0]", where));
      inside(b, fmt::format("{}.line[1]", where));
    }
  }

 private:
  void extent(const Box<double>& b, std::string_view where) const {
    for (int axis = 0; axis < 3; ++axis) {
      if (!(b.hi[axis] > b.lo[axis]))
        fail(fmt::format("{}.max", where), fmt::format("must be greater than {}.min on every axis, but along {} {} <= {}",
                                                       where, "xyz"[axis], b.hi[axis], b.lo[axis]));
    }
  }

  void inside(const Vec3d& p, std::string_view where) const {
    if (s_.walls && !s_.box.contains(p))
      fail(where, fmt::format("{} lies outside the box {}", detail::vec_text(p), detail::box_text(s_.box)));
  }

  void region(const Box<double>& r, std::string_view where) const {
    inside(r.lo, fmt::format("{}.min", where));
    inside(r.hi, fmt::format("{}.max", where));
    extent(r, where);
  }

  void lattice(const LatticeSource& l, std::string_view where) const {
    region(l.region, where);
    const auto n = detail::lattice_counts(l);
    for (int axis = 0; axis < 3; ++axis) {
      if (n[static_cast<std::size_t>(axis)] != 0) continue;
      fail(where, fmt::format("makes no particles: the region is {} long along {}, less than the spacing {}",
                              l.region.extent()[axis], "xyz"[axis], l.spacing));
    }
  }

  void listed(const ListSource& l, std::string_view where) const {
    const std::string positions = fmt::format("{}.positions", where);
    if (l.positions.empty()) fail(positions, "must list at least one position");
    for (std::size_t i = 0; i < l.positions.size(); ++i) inside(l.positions[i], fmt::format("{}[{}]", positions, i));
    // Per-particle arrays must match positions one to one (velocities may be empty: all at rest).
    if (!l.velocities.empty() && l.velocities.size() != l.positions.size())
      fail(fmt::format("{}.velocities", where),
           fmt::format("has {} entries but {} has {}", l.velocities.size(), positions, l.positions.size()));
    if (l.masses.size() != l.positions.size())
      fail(fmt::format("{}.masses", where),
           fmt::format("has {} entries but {} has {}", l.masses.size(), positions, l.positions.size()));
  }

  // What load_scene read from the file, against the scene: the counts, the
  // units the file says it is in, positive masses, the box.
  void snapshot_file(const SnapshotSource& src, std::string_view where) const {
    const std::string key = fmt::format("{}.file", where);
    if (!src.content) fail(key, fmt::format("{} has not been read (load_scene reads it; a Scene built in code must "
                                            "fill SnapshotSource::content)", src.file));
    const SnapshotContent& c = *src.content;
    const std::size_t n = c.positions.size();
    if (n == 0) fail(key, fmt::format("{}: {} holds no particles", src.file, c.group));
    if (c.velocities.size() != n || c.masses.size() != n)
      fail(key, fmt::format("{}: the content read has {} positions, {} velocities and {} masses", src.file, n,
                            c.velocities.size(), c.masses.size()));
    snapshot_units(c, src.file, key);
    for (std::size_t i = 0; i < n; ++i)
      if (!(c.masses[i] > 0))
        fail(key, fmt::format("{}: {}/Masses: particle {} has mass {}; masses must be > 0", src.file, c.group, i,
                              c.masses[i]));
    if (!s_.walls) return;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d p = detail::moved(c.positions[i], src.offset);
      if (!s_.box.contains(p))
        fail(key, fmt::format("{}: {}/Coordinates: particle {} at {}{} lies outside the box {}", src.file, c.group, i,
                              detail::vec_text(p), src.offset == Vec3d{} ? "" : " (with the offset)",
                              detail::box_text(s_.box)));
    }
  }

  // A file that says which units it is in must say the scene's: swirl does
  // not convert (a file in kpc, 10¹⁰ M☉ and km/s is refused, naming its factors).
  void snapshot_units(const SnapshotContent& c, std::string_view file, std::string_view key) const {
    const std::string_view units = enum_name<Units>(kUnitsNames, s_.units);
    if (!c.unit_system.empty() && c.unit_system != units)
      fail(key, fmt::format("{}: /Header/UnitSystem is \"{}\", but the scene's simulation.units is \"{}\": its "
                            "numbers would be taken in the wrong units",
                            file, c.unit_system, units));
    if (!c.cgs_units) return;
    const auto& u = *c.cgs_units;
    const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-9 * b; };
    if (s_.units == Units::SI && near(u[0], 100) && near(u[1], 1000) && near(u[2], 1)) return;
    const std::string factors = fmt::format("/Units gives U_L = {} cm, U_M = {} g, U_t = {} s", u[0], u[1], u[2]);
    if (s_.units == Units::SI)
      fail(key, fmt::format("{}: {}, not SI's m, kg and s (100, 1000, 1): swirl does not convert units; convert the "
                            "file's numbers to SI",
                            file, factors));
    fail(key, fmt::format("{}: {}, physical units, but the scene's simulation.units is \"nbody\" (G = 1): swirl does "
                          "not convert units; use simulation.units = \"si\" with a file in m, kg and s",
                          file, factors));
  }

  // An obstacle's geometry: inside the box (when the scene has one), not degenerate.
  void obstacle_shape(const ObstacleSource& o, std::string_view where) const {
    using Shape = ObstacleSource::Shape;
    const auto key = [&](std::string_view k) { return fmt::format("{}.{}", where, k); };
    // The box [lo, hi] of the obstacle's points must lie in the scene's box.
    const auto within = [&](const Vec3d& lo, const Vec3d& hi, std::string_view k, std::string_view what) {
      if (!s_.walls) return;
      if (!s_.box.contains(lo) || !s_.box.contains(hi))
        fail(key(k), fmt::format("{} reaches outside the box {} (it spans {} to {})", what, detail::box_text(s_.box),
                                 detail::vec_text(lo), detail::vec_text(hi)));
    };
    switch (o.shape) {
      case Shape::Box: {
        inside(o.region.lo, key("min"));
        inside(o.region.hi, key("max"));
        int flat = 0;
        for (int axis = 0; axis < 3; ++axis) {
          if (o.region.hi[axis] < o.region.lo[axis])
            fail(key("max"), fmt::format("must be ≥ {} on every axis, but along {} {} < {}", key("min"), "xyz"[axis],
                                         o.region.hi[axis], o.region.lo[axis]));
          flat += o.region.hi[axis] == o.region.lo[axis] ? 1 : 0;
        }
        if (flat > 1) fail(key("max"), "the obstacle is a line or a point: it needs an extent along two axes at least");
        break;
      }
      case Shape::Sphere: {
        inside(o.center, key("center"));
        const Vec3d r{o.radius, o.radius, o.radius};
        within(o.center - r, o.center + r, "radius", fmt::format("the sphere of radius {}", o.radius));
        break;
      }
      case Shape::Cylinder: {
        inside(o.start, key("start"));
        inside(o.end, key("end"));
        const Vec3d axis = o.end - o.start;
        const double length = norm(axis);
        if (!(length > 0)) fail(key("end"), fmt::format("equals {}: the cylinder has no length", key("start")));
        Vec3d lo, hi;
        for (int a = 0; a < 3; ++a) {  // the end discs' extent along each axis
          const double e = axis[a] / length, reach = o.radius * std::sqrt(std::max(0.0, 1 - e * e));
          lo[a] = std::min(o.start[a], o.end[a]) - reach;
          hi[a] = std::max(o.start[a], o.end[a]) + reach;
        }
        within(lo, hi, "radius", fmt::format("the cylinder of radius {}", o.radius));
        break;
      }
      case Shape::Plane:
        if (!s_.walls) fail(key("kind"), "'obstacle_plane' is clipped to the box: it needs a [box]");
        inside(o.point, key("point"));
        if (!(norm(o.normal) > 0)) fail(key("normal"), "must not be zero");
        break;
      case Shape::Mesh: mesh(o, where); return;
    }
    if (detail::obstacle_count(o) == 0)
      fail(where, fmt::format("makes no boundary particles at spacing {}", o.spacing));
  }

  // A moving obstacle: a motion of a known kind, its directions not zero, a
  // rotation that turns, whole steps for everyone, and (with a box) every one
  // of its particles inside the box at every time: the box's passes would
  // otherwise reflect the prescribed velocities of those outside.
  void motion(const ObstacleSource& o, std::string_view where) const {
    using Kind = boundary::RigidMotion::Kind;
    const boundary::RigidMotion& m = *o.motion;
    const auto key = [&](std::string_view k) { return fmt::format("{}.motion.{}", where, k); };
    const std::string_view name = enum_name<Kind>(boundary::kRigidMotionNames, m.kind);
    if (name.empty()) fail(key("kind"), "is not a valid motion kind");
    if (m.kind == Kind::Piston && !(norm(m.direction) > 0)) fail(key("direction"), "must not be zero");
    if (m.kind != Kind::Piston && !(norm(m.axis) > 0)) fail(key("axis"), "must not be zero");
    if (m.kind == Kind::Rotation && !(m.angular_velocity != 0))
      fail(key("angular_velocity"), "must not be 0 (a rotation that does not turn is a static obstacle)");
    if (s_.time_steps == TimeSteps::Block)
      fail(key("kind"), "moving obstacles need simulation.time_steps = \"global\"");
    if (!s_.walls) return;
    const std::vector<Vec3d> points = obstacle_points(o);
    if (points.empty()) return;
    Vec3d lo = boundary::swept_bounds(m, points.front())[0], hi = lo;
    for (const Vec3d& x : points) {
      const auto b = boundary::swept_bounds(m, x);
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], b[0][a]), hi[a] = std::max(hi[a], b[1][a]);
    }
    if (!s_.box.contains(lo) || !s_.box.contains(hi))
      fail(key(m.kind == Kind::Piston ? "amplitude" : m.kind == Kind::Flap ? "amplitude_deg" : "point"),
           fmt::format("the '{}' motion takes the obstacle outside the box {}: its particles sweep {} to {}; moving "
                       "particles must stay inside the box (a smaller amplitude, or the obstacle further in)",
                       name, detail::box_text(s_.box), detail::vec_text(lo), detail::vec_text(hi)));
  }

  // A mesh obstacle: read, placed at finite coordinates inside the box, and
  // not more boundary particles than kMaxMeshParticles.
  void mesh(const ObstacleSource& o, std::string_view where) const {
    const std::string file_key = fmt::format("{}.file", where);
    if (!o.mesh || o.mesh->triangles.empty())
      fail(file_key, fmt::format("{} has not been read (load_scene reads it; a Scene built in code must fill "
                                 "ObstacleSource::mesh with at least one triangle)",
                                 o.file));
    if (!mesh_indices_valid(*o.mesh))
      fail(file_key, fmt::format("{}: a triangle names a vertex the mesh does not have, or one vertex twice", o.file));
    const std::vector<Vec3d> x = placed_vertices(o);
    Vec3d lo = x.front(), hi = x.front();
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (!std::isfinite(x[i].x) || !std::isfinite(x[i].y) || !std::isfinite(x[i].z))
        fail(fmt::format("{}.scale", where), fmt::format("{}: vertex {} lands at {}: scale, rotate_deg and translate "
                                                         "must keep the mesh finite",
                                                         o.file, i, detail::vec_text(x[i])));
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], x[i][a]), hi[a] = std::max(hi[a], x[i][a]);
    }
    if (s_.walls && (!s_.box.contains(lo) || !s_.box.contains(hi)))
      fail(fmt::format("{}.translate", where),
           fmt::format("{}: the placed mesh reaches outside the box {} (it spans {} to {}); move it with translate, "
                       "or shrink it with scale",
                       o.file, detail::box_text(s_.box), detail::vec_text(lo), detail::vec_text(hi)));
    const std::uint64_t n = mesh_point_count(o);
    if (n > kMaxMeshParticles)
      fail(fmt::format("{}.spacing", where),
           fmt::format("{}: the mesh's {} triangles spanning {} to {} would make {} boundary particles at spacing {}, "
                       "more than the limit of {} (2^24) per mesh; use a larger spacing or a smaller mesh",
                       o.file, o.mesh->triangles.size(), detail::vec_text(lo), detail::vec_text(hi),
                       fmt::format("{}{}", n > 16 * kMaxMeshParticles ? "up to about " : "", count_text(n)),
                       o.spacing, kMaxMeshParticles));
  }

  // A fluid_sphere or fluid_mesh: inside the box, a mesh read, finite, closed
  // and within kMaxFillWork, and at least one particle.
  void fill(const FluidFillSource& f, std::string_view where) const {
    const auto key = [&](std::string_view k) { return fmt::format("{}.{}", where, k); };
    if (f.shape == FluidFillSource::Shape::Mesh) {
      if (!f.mesh || f.mesh->triangles.empty())
        fail(key("file"), fmt::format("{} has not been read (load_scene reads it; a Scene built in code must fill "
                                      "FluidFillSource::mesh with at least one triangle)",
                                      f.file));
      if (!mesh_indices_valid(*f.mesh))
        fail(key("file"), fmt::format("{}: a triangle names a vertex the mesh does not have, or one vertex twice", f.file));
      if (const std::string problem = mesh_closure_problem(*f.mesh); !problem.empty())
        fail(key("file"), fmt::format("{}: {}; a fluid_mesh fills the inside of a closed surface", f.file, problem));
      const std::vector<Vec3d> x = placed_fill_vertices(f);
      for (std::size_t i = 0; i < x.size(); ++i)
        if (!std::isfinite(x[i].x) || !std::isfinite(x[i].y) || !std::isfinite(x[i].z))
          fail(key("scale"), fmt::format("{}: vertex {} lands at {}: scale, rotate_deg and translate must keep the "
                                         "mesh finite",
                                         f.file, i, detail::vec_text(x[i])));
    }
    const Box<double> b = fill_bounds(f);
    if (s_.walls && (!s_.box.contains(b.lo) || !s_.box.contains(b.hi))) {
      if (f.shape == FluidFillSource::Shape::Mesh)
        fail(key("translate"), fmt::format("{}: the placed mesh reaches outside the box {} (it spans {} to {}); move "
                                           "it with translate, or shrink it with scale",
                                           f.file, detail::box_text(s_.box), detail::vec_text(b.lo),
                                           detail::vec_text(b.hi)));
      fail(key("radius"), fmt::format("the sphere of radius {} about {} reaches outside the box {}", f.radius,
                                      detail::vec_text(f.center), detail::box_text(s_.box)));
    }
    const std::uint64_t bound = fill_lattice_bound(f);
    if (bound > detail::kMaxParticles)
      fail(key("spacing"), fmt::format("the lattice over the shape's bounds {} to {} has {} points, more than the "
                                       "limit of {} (2^31); is the spacing too small?",
                                       detail::vec_text(b.lo), detail::vec_text(b.hi), count_text(bound),
                                       detail::kMaxParticles));
    if (f.shape == FluidFillSource::Shape::Mesh &&
        detail::mul_sat(bound, f.mesh->triangles.size()) > kMaxFillWork)
      fail(key("spacing"), fmt::format("{}: {} lattice points against {} triangles is more than {} (2^34) inside "
                                       "tests; use a larger spacing or a mesh of fewer triangles",
                                       f.file, bound, f.mesh->triangles.size(), kMaxFillWork));
    if (detail::source_count(f) == 0)
      fail(std::string(where), fmt::format("makes no particles: no lattice point at spacing {} lies inside the {}",
                                           f.spacing, f.shape == FluidFillSource::Shape::Mesh ? "mesh" : "sphere"));
  }

  void stellar(const StellarSource& m, std::string_view where) const {
    const std::string_view kind = enum_name<StellarSource::Model>(kStellarModelNames, m.model);
    if (s_.walls)
      fail(fmt::format("{}.kind", where),
           fmt::format("'{}' is a self-gravitating model: it needs open space (no [box])", kind));
    if (m.model == StellarSource::Model::DiskGalaxy) {
      // Disk and halo each need a particle (disk_galaxy() rounds the disk's share).
      const double disk = std::round(m.disk.disk_particles * static_cast<double>(m.count));
      if (disk < 1 || disk > static_cast<double>(m.count) - 1)
        fail(fmt::format("{}.disk_particles", where),
             fmt::format("{} of {} particles leaves the disk or the halo empty", m.disk.disk_particles, m.count));
      return;
    }
    if (m.model != StellarSource::Model::PlummerCollision) return;
    const auto& c = m.collision;
    const auto key = [&](std::string_view k) { return fmt::format("{}.{}", where, k); };
    if (m.count < 2) fail(key("count"), "a collision needs at least 2 particles");
    if (!(c.impact_parameter < c.separation))
      fail(key("impact_parameter"), fmt::format("must be in [0, {}), got {}", c.separation, c.impact_parameter));
    // Each sphere needs a particle, and the geometry (d², the parabolic speed √(2/d)) must stay finite.
    const double n1 = std::round(c.mass_fraction * static_cast<double>(m.count));
    if (n1 < 1 || n1 > static_cast<double>(m.count) - 1)
      fail(key("mass_fraction"), fmt::format("{} of {} particles leaves one sphere empty", c.mass_fraction, m.count));
    if (!std::isfinite(c.separation * c.separation) || !std::isfinite(std::sqrt(2.0 / c.separation)))
      fail(key("separation"), fmt::format("{} is out of the usable range", c.separation));
  }

  const Scene& s_;
  std::string file_;
};

}  // namespace

void validate(const Scene& scene) {
  const Checker check(scene);
  check.keys();
  check.time();
  check.units();
  check.box();
  check.nbody();
  check.sph();
  check.output();
  check.sources();
  check.boundary();
  check.probes();
  check.inlets_and_outlets();
}

double dense_cell_table_keys(const Scene& scene) {
  if (!scene.sph || !scene.walls || scene.sph->neighbour_search != sph::NeighbourSearch::Grid ||
      scene.sph->cell_table != spatial::CellTable::Dense)
    return 0;
  const double cell = scene.sph->smoothing_length + scene.sph->grid_skin;
  double keys = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const double cells = std::max(1.0, std::ceil((scene.box.hi[axis] - scene.box.lo[axis]) / cell));
    keys *= scene.sph->cell_order == spatial::CellOrder::Morton ? std::exp2(std::ceil(std::log2(cells))) : cells;
  }
  return keys;
}

std::vector<std::string> advisories(const Scene& scene) {
  std::vector<std::string> out;
  const std::string file = scene.file.empty() ? std::string("scene") : scene.file;
  if (scene.nbody && scene.nbody->softening == 0 && count_particles(scene) > 1)
    out.push_back(file + ": nbody.softening = 0: the force between two particles grows without bound as they "
                         "approach (1/r²), so one close pair can ruin the energy of the whole run; give a softening of "
                         "a few percent of the mean particle spacing, or keep 0 only for a few well-separated bodies "
                         "(" +
                  (scene.max_energy_error > 0
                       ? fmt::format("the run stops if its relative energy error passes simulation.max_energy_error = {:g}",
                                     scene.max_energy_error)
                       : std::string("simulation.max_energy_error = 0: nothing stops a run whose energy is ruined")) +
                  ")");
  return out;
}

}  // namespace swirl::scene
