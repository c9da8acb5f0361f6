#include "swirl/scene/load.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "messages.hpp"
#include "sources.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/io/mesh_file.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/scene/keys.hpp"
#include "swirl/scene/validate.hpp"
#include "swirl/sph/lattice_mass.hpp"

namespace swirl::scene {
namespace {

using Keys = std::span<const std::string_view>;
using detail::raise;

// Optimal string alignment distance: Levenshtein plus transpositions, the usual typos.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

std::string suggestion(std::string_view key, Keys known) {
  std::string_view best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const auto candidate : known) {
    const std::size_t limit = std::max<std::size_t>(1, (candidate.size() + 1) / 3);
    // Also keeps the quadratic distance cheap for absurdly long keys.
    if (key.size() > candidate.size() + limit || candidate.size() > key.size() + limit) continue;
    const std::size_t distance = edit_distance(key, candidate);
    if (distance <= limit && distance < best_distance) best = candidate, best_distance = distance;
  }
  return best.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", best);
}


std::string_view a_type(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

std::string quoted_list(Keys names) {
  std::string out;
  for (const auto name : names) out += fmt::format("{}'{}'", out.empty() ? "" : ", ", name);
  return out;
}

// ---- What each table may hold, from the declarations in keys.cpp ------------

// The names directly under `path` ("" is the root): the next segment of every
// declared key below it, so [sph] holds "grid" and "hash" as well as its keys.
std::vector<std::string_view> known_keys(std::string_view path) {
  std::vector<std::string_view> out;
  const auto add = [&](std::string_view name) {
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  };
  if (path.empty())
    for (const auto section : scene_sections()) add(section);
  for (const auto& spec : scene_keys()) {
    std::string_view rest = spec.key;
    if (!path.empty()) {
      if (!(rest.starts_with(path) && rest.size() > path.size() && rest[path.size()] == '.')) continue;
      rest.remove_prefix(path.size() + 1);
    }
    add(rest.substr(0, rest.find('.')));
  }
  return out;
}

std::vector<std::string_view> kind_names() {
  std::vector<std::string_view> out;
  for (const auto& kind : source_kinds()) out.push_back(kind.name);
  return out;
}

// The names a source's table may hold: `kind` and its keys, a dotted key by
// its table ("motion" for "motion.kind", ...).
std::vector<std::string_view> keys_of(const SourceKind& kind) {
  std::vector<std::string_view> out{"kind"};
  for (const auto& spec : kind.keys) {
    const std::string_view name = spec.key.substr(0, spec.key.find('.'));
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  }
  return out;
}

// Every key some kind takes: checked before `kind`, so that a misspelt "kind"
// is reported as such.
std::vector<std::string_view> any_source_keys() {
  std::vector<std::string_view> out;
  for (const auto& kind : source_kinds())
    for (const auto key : keys_of(kind))
      if (std::find(out.begin(), out.end(), key) == out.end()) out.push_back(key);
  return out;
}

const KeySpec<Scene>& spec_of(std::string_view key) {
  for (const auto& spec : scene_keys())
    if (spec.key == key) return spec;
  throw std::logic_error(fmt::format("scene key '{}' is not declared", key));
}

template <class Owner>
const KeySpec<Owner>& spec_in(std::span<const KeySpec<Owner>> specs, std::string_view key) {
  for (const auto& spec : specs)
    if (spec.key == key) return spec;
  throw std::logic_error(fmt::format("scene key '{}' is not declared", key));
}

// ---- Reading TOML nodes ------------------------------------------------------

// Values read from nodes; `where` is the dotted key used in messages.
class Reader {
 public:
  explicit Reader(std::string_view file) : file_(file) {}

  std::string_view file() const { return file_; }
  [[noreturn]] void fail(std::string_view where, std::string_view reason) const { detail::fail(file_, where, reason); }
  [[noreturn]] void wrong_type(std::string_view where, std::string_view expected, const toml::node& node) const {
    fail(where, fmt::format("expected {}, got {}", expected, a_type(node)));
  }

  double number(const toml::node& node, std::string_view where, const Range& range) const {
    double v = 0;
    if (const auto* i = node.as_integer()) {
      v = static_cast<double>(i->get());
    } else if (const auto* f = node.as_floating_point()) {
      v = f->get();
    } else {
      wrong_type(where, "a number", node);
    }
    if (!std::isfinite(v)) fail(where, fmt::format("must be finite, got {}", v));
    if (!range.contains(v)) fail(where, fmt::format("must be {}, got {}", range.text(), v));
    return v;
  }

  std::uint64_t integer(const toml::node& node, std::string_view where, const Range& range) const {
    const auto* i = node.as_integer();
    if (!i) wrong_type(where, "an integer", node);
    // Compared as doubles: every bound in keys.cpp is exact in a double.
    if (!range.contains(static_cast<double>(i->get()))) fail(where, fmt::format("must be {}, got {}", range.text(), i->get()));
    return static_cast<std::uint64_t>(i->get());
  }

  Vec3d vec3(const toml::node& node, std::string_view where) const {
    const auto* array = node.as_array();
    if (!array) wrong_type(where, "an array of 3 numbers", node);
    if (array->size() != 3) fail(where, fmt::format("expected an array of 3 numbers, got {} elements", array->size()));
    Vec3d v;
    for (int axis = 0; axis < 3; ++axis)
      v[axis] = number((*array)[static_cast<std::size_t>(axis)], fmt::format("{}[{}]", where, axis), Range{});
    return v;
  }

  std::string_view choice(const toml::node& node, std::string_view where, Keys allowed, std::string_view what) const {
    const auto* s = node.as_string();
    if (!s) wrong_type(where, "a string", node);
    const auto it = std::find(allowed.begin(), allowed.end(), s->get());
    if (it == allowed.end())
      fail(where, fmt::format("unknown {} '{}' (allowed: {})", what, s->get(), quoted_list(allowed)));
    return *it;
  }

  const toml::array& array(const toml::node& node, std::string_view where, std::string_view expected) const {
    const auto* a = node.as_array();
    if (!a) wrong_type(where, expected, node);
    return *a;
  }

  // The value of a declared key, of its type, within its range or names.
  template <class Owner>
  KeyValue value(const toml::node& node, std::string_view where, const KeySpec<Owner>& spec) const {
    switch (spec.type) {
      case KeyType::Number: return number(node, where, spec.range);
      case KeyType::Integer: return integer(node, where, spec.range);
      case KeyType::Boolean: {
        const auto* b = node.as_boolean();
        if (!b) wrong_type(where, "a boolean (true or false)", node);
        return b->get();
      }
      case KeyType::Name: return choice(node, where, spec.names, spec.noun);
      case KeyType::NameList: {
        if (node.is_string()) return std::vector{choice(node, where, spec.names, spec.noun)};
        const auto& list = array(node, where, "a string or an array of strings");
        std::vector<std::string_view> names;
        for (std::size_t i = 0; i < list.size(); ++i)
          names.push_back(choice(list[i], fmt::format("{}[{}]", where, i), spec.names, spec.noun));
        detail::check_value(spec, names, file_, where);  // not empty, none twice
        return names;
      }
      case KeyType::Vector: return vec3(node, where);
      case KeyType::Text: {
        const auto* s = node.as_string();
        if (!s) wrong_type(where, "a string", node);
        const std::string_view text = s->get();  // the node outlives the set() that copies it
        detail::check_value(spec, KeyValue{text}, file_, where);
        return text;
      }
      case KeyType::VectorList:
      case KeyType::NumberList: break;  // read by hand (ListSource), with messages of their own
    }
    throw std::logic_error(fmt::format("{}: no generic reader for this key", where));
  }

 private:
  std::string_view file_;
};

// One table of the scene, possibly absent (then every key is missing).
class Table {
 public:
  Table(const Reader& reader, const toml::table* table, std::string path)
      : r_(reader), table_(table), path_(std::move(path)) {}

  std::string key(std::string_view k) const { return path_.empty() ? std::string(k) : fmt::format("{}.{}", path_, k); }
  const std::string& path() const { return path_; }
  const Reader& reader() const { return r_; }
  [[noreturn]] void fail(std::string_view k, std::string_view reason) const { r_.fail(key(k), reason); }

  const toml::node* find(std::string_view k) const { return table_ ? table_->get(k) : nullptr; }
  bool present() const { return table_ != nullptr; }
  const toml::node& need(std::string_view k, std::string_view hint = "") const {
    if (const auto* node = find(k)) return *node;
    fail(k, fmt::format("missing required key{}", hint));
  }

  void only(Keys known, std::string_view what = "unknown key") const {
    if (!table_) return;
    // Tables iterate alphabetically; report the unknown key that comes first in the file.
    const toml::key* first = nullptr;
    for (auto&& [k, node] : *table_) {
      const bool known_key = std::find(known.begin(), known.end(), k.str()) != known.end();
      if (!known_key && (!first || k.source().begin < first->source().begin)) first = &k;
    }
    if (first) fail(first->str(), fmt::format("{}{}", what, suggestion(first->str(), known)));
  }

  Table table(std::string_view k) const {
    const auto* node = find(k);
    if (node && !node->is_table()) r_.wrong_type(key(k), "a table", *node);
    return Table(r_, node ? node->as_table() : nullptr, key(k));
  }

  // A declared key named `k` in this table: its value if present, else its
  // default from the keys read before it (or the field's own default).
  template <class Owner>
  void read(const KeySpec<Owner>& spec, std::string_view k, Owner& owner) const {
    if (const auto* node = find(k)) {
      spec.set(owner, r_.value(*node, key(k), spec));
      return;
    }
    if (spec.required) need(k);
    if (spec.context_default)
      if (const auto value = spec.context_default(owner)) spec.set(owner, *value);
  }

  // Every generic scene key directly in this table, in declaration order.
  void read_scene_keys(Scene& s) const {
    for (const auto& spec : scene_keys()) {
      std::string_view rest = spec.key;
      if (spec.custom_read || !rest.starts_with(path_) || rest.size() <= path_.size() || rest[path_.size()] != '.')
        continue;
      rest.remove_prefix(path_.size() + 1);
      if (rest.find('.') == std::string_view::npos) read(spec, rest, s);
    }
  }

  double number(const KeySpec<Scene>& spec, std::string_view k) const { return r_.number(need(k), key(k), spec.range); }

 private:
  const Reader& r_;
  const toml::table* table_;
  std::string path_;
};

// ---- The sections --------------------------------------------------------------

// The root key `format`, before anything else: a newer file may hold keys this
// build does not know, and should be refused for its version, not for them.
void read_format(const Table& top, Scene& s) {
  const auto* node = top.find("format");
  if (!node) return;  // the current format
  const auto* i = node->as_integer();
  if (!i) top.reader().wrong_type("format", "an integer", *node);
  if (const std::string problem = detail::format_version_problem(i->get()); !problem.empty()) top.fail("format", problem);
  s.format_version = static_cast<std::uint32_t>(i->get());
}

void read_simulation(const Table& t, Scene& s) {
  t.only(known_keys("simulation"));
  t.read_scene_keys(s);
  // dt: a number, or "adaptive" (then dt_max is the step's cap; see resolve_time_step()).
  const auto* dt_node = t.find("dt");
  s.adaptive_dt = dt_node && dt_node->is_string() && dt_node->value<std::string>() == "adaptive";
  if (!s.adaptive_dt) s.dt = t.number(spec_of("simulation.dt"), "dt");
  for (const std::string_view k : {"dt_max", "dt_min"})
    if (!s.adaptive_dt && t.find(k)) t.fail(k, fmt::format("needs {} = \"adaptive\" (a fixed dt is the step itself)", t.key("dt")));
  if (s.time_steps != TimeSteps::Block && t.find("max_bin"))
    t.fail("max_bin", fmt::format("only with {} = \"block\"", t.key("time_steps")));
  const bool has_end_time = t.find("end_time") != nullptr;
  const bool has_steps = t.find("steps") != nullptr;
  if (has_end_time && has_steps)
    t.fail("steps", fmt::format("cannot be given together with {}; give one of them", t.key("end_time")));
  if (!has_end_time && !has_steps) t.need("end_time", fmt::format(" (give end_time or {})", t.key("steps")));
  if (has_end_time) t.read(spec_of("simulation.end_time"), "end_time", s);
  else t.read(spec_of("simulation.steps"), "steps", s);
}

// dt = "adaptive": the cap dt_max (scene.dt) and the floor dt_min, once the
// solvers and the output interval are known.
void resolve_time_step(const Table& t, Scene& s) {
  if (!s.adaptive_dt) return;
  const bool limited = s.sph || s.nbody;
  std::optional<double> fallback;
  if (limited && s.output_interval > 0) fallback = s.output_interval;
  else if (limited && s.end_time) fallback = *s.end_time;
  if (!t.find("dt_max") && !fallback)
    t.need("dt_max", limited ? " (dt = \"adaptive\" with neither an output interval nor an end_time needs a cap)"
                             : " (dt = \"adaptive\" without [sph] or [nbody]: no condition limits the step, so give its size)");
  s.dt = t.find("dt_max") ? t.number(spec_of("simulation.dt_max"), "dt_max") : *fallback;
  if (t.find("dt_min")) s.dt_min = t.number(spec_of("simulation.dt_min"), "dt_min");
}

// [sph]. The smoothing length is given, or derived from a neighbour count and
// the spacing of the first fluid block (volume per particle = spacing³).
void read_sph(const Table& top, Scene& s) {
  if (!top.find("sph")) return;
  const Table t = top.table("sph");
  t.only(known_keys("sph"));
  const Table hash = t.table("hash");
  hash.only(known_keys("sph.hash"));
  const Table grid = t.table("grid");
  grid.only(known_keys("sph.grid"));
  const Table dfsph = t.table("dfsph");
  dfsph.only(known_keys("sph.dfsph"));
  s.sph.emplace();
  t.read_scene_keys(s);
  hash.read_scene_keys(s);
  grid.read_scene_keys(s);
  if (t.find("dfsph") && s.sph->method != sph::SphMethod::Dfsph)
    t.fail("dfsph", "the [sph.dfsph] settings need sph.method = \"dfsph\"");
  dfsph.read_scene_keys(s);
  const bool has_h = t.find("smoothing_length") != nullptr, has_k = t.find("neighbours") != nullptr;
  if (has_h && has_k) t.fail("neighbours", fmt::format("cannot be given together with {}", t.key("smoothing_length")));
  if (has_h) {
    s.sph->smoothing_length = t.number(spec_of("sph.smoothing_length"), "smoothing_length");
    return;
  }
  const double k = t.number(spec_of("sph.neighbours"), "neighbours");
  // The spacing of the first fluid block sets the volume per particle.
  const auto* list = top.find("particles") ? top.find("particles")->as_array() : nullptr;
  const toml::node* spacing = nullptr;
  for (std::size_t i = 0; list && i < list->size() && !spacing; ++i) {
    const auto* src = (*list)[i].as_table();
    const auto* kind = src ? src->get("kind") : nullptr;
    const auto name = kind ? kind->value<std::string>() : std::nullopt;
    if (name == "fluid_block" || name == "fluid_sphere" || name == "fluid_mesh") spacing = src->get("spacing");
  }
  if (!spacing)
    t.fail("neighbours", fmt::format("needs a [[particles]] source of kind 'fluid_block', 'fluid_sphere' or "
                                     "'fluid_mesh' to size h from "
                                     "(or give {})", t.key("smoothing_length")));
  const double s0 = t.reader().number(*spacing, "particles[].spacing", Range{0, std::numeric_limits<double>::infinity(), true, false});
  s.sph->smoothing_length = sph::smoothing_length_for_neighbours(k, s0 * s0 * s0);
}

// [nbody]: self-gravity. Keys whose defaults follow the scheme and the tree
// (tree, multipole, opening_criterion, walk) come after them in keys.cpp.
void read_nbody(const Table& top, Scene& s) {
  if (!top.find("nbody")) return;
  const Table t = top.table("nbody");
  t.only(known_keys("nbody"));
  s.nbody.emplace();
  t.read_scene_keys(s);
}

void read_box(const Table& top, Scene& s) {
  const Table t = top.table("box");
  t.only(known_keys("box"));
  s.walls = true;
  t.read_scene_keys(s);
}

// [random_box] with the root key `particles` = N: the thesis's section 5 set-up.
void read_random_box(const Table& top, Scene& s) {
  const Table t = top.table("random_box");
  t.only(known_keys("random_box"));
  if (!s.sph) t.fail("neighbours", "a random box is sized from sph.smoothing_length: add an [sph] section");
  const Table box = top.table("box");
  box.only(known_keys("box"));
  if (box.find("min") || box.find("max"))
    top.fail("box", "min and max are derived from the random box (L³ = N·(4/3)π h³ / k); remove them");
  if (box.find("walls")) top.fail("box.walls", "a random box has the thesis's clamp walls only; remove it");
  s.walls = true;
  box.read(spec_of("box.restitution"), "restitution", s);
  s.random_box = Scene::RandomBox{};
  t.read_scene_keys(s);
  top.read(spec_of("particles"), "particles", s);
  const Scene::RandomBox& rb = *s.random_box;
  const double h = s.sph->smoothing_length;
  const double side =
      std::cbrt(static_cast<double>(rb.particles) * 4.0 / 3.0 * std::numbers::pi * h * h * h / rb.neighbours);
  s.box = {{0, 0, 0}, {side, side, side}};
  RandomSource src;
  src.region = s.box;
  src.count = rb.particles;
  src.seed = rb.seed;
  src.mass = s.sph->rest_density * side * side * side / static_cast<double>(rb.particles);
  // Extreme h, k or rest density can overflow or underflow the derived box and mass.
  if (!(side > 0) || !std::isfinite(side) || !(src.mass > 0) || !std::isfinite(src.mass))
    t.fail("neighbours", fmt::format("the random box derived from sph.smoothing_length = {}, sph.rest_density = {} "
                                     "and neighbours = {} has side {} and particle mass {}: not usable",
                                     h, s.sph->rest_density, rb.neighbours, side, src.mass));
  s.sources.emplace_back(src);
}

void read_output(const Table& t, Scene& s) {
  t.only(known_keys("output"));
  t.read_scene_keys(s);
}

// A list source's arrays, read by hand for their messages.
void read_list(const Table& t, ListSource& src) {
  const Reader& r = t.reader();
  const std::string where = t.key("positions");
  const auto& positions = r.array(t.need("positions"), where, "an array of [x, y, z] positions");
  for (std::size_t i = 0; i < positions.size(); ++i)
    src.positions.push_back(r.vec3(positions[i], fmt::format("{}[{}]", where, i)));
  const auto& specs = kind_of(ListSource{}).keys;
  if (const auto* node = t.find("velocities")) {
    const auto& velocities = r.array(*node, t.key("velocities"), "an array of [vx, vy, vz] velocities");
    for (std::size_t i = 0; i < velocities.size(); ++i)
      src.velocities.push_back(r.vec3(velocities[i], fmt::format("{}[{}]", t.key("velocities"), i)));
  }
  const bool has_mass = t.find("mass") != nullptr;
  const bool has_masses = t.find("masses") != nullptr;
  if (has_mass && has_masses)
    t.fail("masses", fmt::format("cannot be given together with {}; give one of them", t.key("mass")));
  if (has_mass) {
    src.masses.assign(positions.size(), r.number(*t.find("mass"), t.key("mass"), spec_in<ParticleSource>(specs, "mass").range));
  } else if (has_masses) {
    const auto& masses = r.array(*t.find("masses"), t.key("masses"), "an array of numbers");
    const Range& range = spec_in<ParticleSource>(specs, "masses").range;
    for (std::size_t i = 0; i < masses.size(); ++i)
      src.masses.push_back(r.number(masses[i], fmt::format("{}[{}]", t.key("masses"), i), range));
  } else {
    t.need("mass", fmt::format(" (give mass, or {} with one per position)", t.key("masses")));
  }
}

// A file a source names (its `file` key): resolved against the scene file's
// folder, once, to an absolute, lexically normal path written back into the
// key (parse_scene saves it in the run's scene.toml), and refused when it does
// not exist. `resume_note` adds to the missing file's message.
std::filesystem::path resolve_scene_file(const Table& t, std::string& file, std::string_view resume_note = {}) {
  namespace fs = std::filesystem;
  const fs::path base = fs::path(std::string(t.reader().file())).parent_path();
  std::error_code ec;
  const fs::path path = fs::absolute(base / fs::path(file), ec).lexically_normal();
  if (ec) t.fail("file", fmt::format("'{}' cannot be made absolute: {}", file, ec.message()));
  file = path.string();
  if (!fs::exists(path, ec))
    t.fail("file", fmt::format("{}: no such file (the scene reads it whenever it is loaded, `swirl run --resume` "
                               "included{}: put the file back at this path)",
                               file, resume_note));
  return path;
}

// A snapshot source's file: its path resolved and its particles read.
//
// The path is relative to the scene file's folder (to the working directory
// for a scene without one: "<dict>", "<toml>"), and is resolved here, once, to
// an absolute, lexically normal path, which parse_scene writes back into the
// scene's TOML: the copy saved with a run then names the same file from any
// working directory (`swirl run --resume OUT` reads OUT/scene.toml), and the
// scene hash sees the same path in the first run and in the resume.
//
// The file is read whole, now: its refusals (a missing file or group, a
// wrong shape, a NaN) come when the scene is loaded, as every other scene
// error does, before a run folder exists; the count is exact for validation
// and the memory estimate; and the particles validated are the ones built.
// A resume reads it again (the scene is rebuilt before the checkpoint
// replaces its particles), so the message for a missing file says so.
void read_snapshot_file(const Table& t, SnapshotSource& src) {
  const std::filesystem::path path =
      resolve_scene_file(t, src.file, ", which rebuilds the scene before the checkpoint replaces its particles");
  try {
    std::optional<int> type;
    if (src.part_type) {
      type = static_cast<int>(*src.part_type);
    } else {
      // The default is the only type with particles; several are a choice the scene must make.
      // (None: read_snapshot's rule for an empty file, and validate() refuses the empty source.)
      const auto counts = io::snapshot_particle_counts(path);
      std::string groups, types;
      int present = 0;
      for (int k = 0; k < io::kGadgetTypes; ++k) {
        if (counts[static_cast<std::size_t>(k)] == 0) continue;
        groups += fmt::format("{}/PartType{} ({})", groups.empty() ? "" : ", ", k, counts[static_cast<std::size_t>(k)]);
        types += fmt::format("{}{}", types.empty() ? "" : " or ", k);
        type = k;
        ++present;
      }
      if (present > 1)
        t.fail("part_type", fmt::format("missing, and {} has particles in {}: give part_type = {} (one [[particles]] "
                                        "source per type)",
                                        src.file, groups, types));
    }
    io::SnapshotFile file = io::read_snapshot(path, type);
    auto content = std::make_shared<SnapshotContent>();
    content->group = fmt::format("/PartType{}", static_cast<int>(file.info.type));
    const auto rows = [&](const char* name) -> const std::vector<double>& { return file.datasets.at(name).values; };
    const auto& x = rows("Coordinates");
    const auto& v = rows("Velocities");
    content->masses = rows("Masses");
    content->positions.resize(file.count);
    content->velocities.resize(file.count);
    for (std::size_t i = 0; i < file.count; ++i) {
      content->positions[i] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
      content->velocities[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
    }
    content->unit_system = std::move(file.unit_system);
    if (file.cgs_units)
      content->cgs_units = std::array<double, 3>{file.cgs_units->length, file.cgs_units->mass, file.cgs_units->time};
    src.content = std::move(content);
  } catch (const io::IoError& e) {
    t.fail("file", e.what());  // names the file, the group or dataset, and the reason
  }
}

// An obstacle_mesh's file: its path resolved as a snapshot's is (against the
// scene file's folder, once, to an absolute path that parse_scene writes back
// into the scene's TOML) and its triangles read now, so that a missing or
// broken file is refused when the scene is loaded, and validation counts the
// particles that will be built. A resume reads it again.
template <class Source>  // ObstacleSource or FluidFillSource
void read_mesh_file(const Table& t, Source& src) {
  const std::filesystem::path path = resolve_scene_file(t, src.file);
  try {
    src.mesh = std::make_shared<const io::TriangleMesh>(io::read_triangle_mesh(path));
  } catch (const io::IoError& e) {
    t.fail("file", e.what());  // names the file and the reason
  }
}

// An obstacle's `motion` table: its kind first, which says which of the
// declared "motion.*" keys it takes (those whose field it has), then those.
void read_motion(const Table& t, const SourceKind& kind, ParticleSource& source) {
  const Reader& r = t.reader();
  const Table m = t.table("motion");
  std::vector<std::string_view> names;
  for (const auto& entry : boundary::kRigidMotionNames) names.push_back(entry.name);
  const std::string_view name = r.choice(m.need("kind"), m.key("kind"), names, "motion");
  auto& obstacle = std::get<ObstacleSource>(source);
  obstacle.motion.emplace();
  obstacle.motion->kind = *enum_value<boundary::RigidMotion::Kind>(boundary::kRigidMotionNames, name);
  constexpr std::string_view prefix = "motion.";
  std::vector<std::string_view> known;
  for (const auto& spec : kind.keys)
    if (spec.key.starts_with(prefix) && spec.get(source)) known.push_back(spec.key.substr(prefix.size()));
  m.only(known, fmt::format("unknown key for a '{}' motion", name));
  for (const auto& spec : kind.keys) {
    if (!spec.key.starts_with(prefix) || !spec.get(source)) continue;
    const std::string_view rest = spec.key.substr(prefix.size());
    if (rest != "kind") m.read(spec, rest, source);
  }
}

// Boundary particles are sampled at the fluid's spacing unless told: the
// walls (box.walls = "particles") and every obstacle without a `spacing` take
// the first fluid_block's.
void resolve_boundary_spacing(const Table& top, Scene& s, double fluid) {
  for (std::size_t i = 0; i < s.sources.size(); ++i) {
    auto* obstacle = std::get_if<ObstacleSource>(&s.sources[i]);
    if (!obstacle || obstacle->spacing > 0) continue;
    if (fluid == 0)
      top.fail(fmt::format("particles[{}].spacing", i),
               "missing: the scene has no [[particles]] source of kind 'fluid_block' to take the boundary particles' "
               "spacing from");
    obstacle->spacing = fluid;
  }
  if (s.walls && s.wall_kind == Walls::Particles) {
    if (!s.sph) top.fail("box.walls", "\"particles\" are boundary particles of the fluid: it needs an [sph] section");
    if (fluid == 0)
      top.fail("box.walls", "\"particles\" samples the walls at the fluid's spacing: it needs a [[particles]] source "
                            "of kind 'fluid_block'");
    s.wall_spacing = fluid;
  }
}

void read_particles(const Table& top, Scene& s) {
  const Reader& r = top.reader();
  if (s.random_box) return;  // its one source was made by read_random_box()
  const auto* node = top.find("particles");
  if (!node) r.fail("particles", "no particles: the scene needs at least one [[particles]] source");
  const auto& list = r.array(*node, "particles", "an array of tables ([[particles]])");
  const std::vector<std::string_view> any_key = any_source_keys(), kinds = kind_names();
  double fluid_spacing = 0;  // the first fluid_block's
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = fmt::format("particles[{}]", i);
    if (!list[i].is_table()) r.wrong_type(where, "a table", list[i]);
    const Table t(r, list[i].as_table(), where);
    t.only(any_key);  // first, so that a misspelt "kind" is reported as such
    const std::string_view name = r.choice(t.need("kind"), t.key("kind"), kinds, "kind");
    const SourceKind& kind = *std::find_if(source_kinds().begin(), source_kinds().end(),
                                           [&](const SourceKind& k) { return k.name == name; });
    t.only(keys_of(kind), fmt::format("unknown key for kind '{}'", kind.name));
    ParticleSource source = kind.prototype;
    for (const auto& spec : kind.keys)
      if (!spec.custom_read) t.read(spec, spec.key, source);
    if (auto* list_source = std::get_if<ListSource>(&source)) read_list(t, *list_source);
    if (auto* snapshot = std::get_if<SnapshotSource>(&source)) read_snapshot_file(t, *snapshot);
    auto* fill = std::get_if<FluidFillSource>(&source);
    if (kind.name == "fluid_block" || fill) {
      // Its mass is the one that gives the rest density (a fill's is the fluid_block's at its spacing).
      double& spacing = fill ? fill->spacing : std::get<LatticeSource>(source).spacing;
      double& mass = fill ? fill->mass : std::get<LatticeSource>(source).mass;
      if (fluid_spacing == 0) fluid_spacing = spacing;
      if (!s.sph)
        t.fail("kind", fmt::format("a '{}' needs an [sph] section (its mass comes from sph.rest_density)", kind.name));
      if (s.sph->smoothing_length / spacing > 1000)
        t.fail("spacing", fmt::format("is over 1000 times smaller than sph.smoothing_length = {}", s.sph->smoothing_length));
      mass = sph::lattice_mass_for_density(spacing, s.sph->smoothing_length, s.sph->rest_density,
                                           s.sph->method == sph::SphMethod::Dfsph ? s.sph->kernel
                                                                                  : sph::SphKernel::Thesis);
      if (fill && fill->shape == FluidFillSource::Shape::Mesh) read_mesh_file(t, *fill);
    }
    if (auto* obstacle = std::get_if<ObstacleSource>(&source)) {
      if (!s.sph)
        t.fail("kind", fmt::format("'{}' is sampled by boundary particles of the fluid: it needs an [sph] section",
                                   kind.name));
      if (const auto* given = t.find("spacing"))
        obstacle->spacing = r.number(*given, t.key("spacing"), spec_in<ParticleSource>(kind.keys, "spacing").range);
      obstacle->clip = s.box;
      if (obstacle->shape == ObstacleSource::Shape::Mesh) read_mesh_file(t, *obstacle);
      if (t.find("motion")) read_motion(t, kind, source);
    }
    s.sources.push_back(std::move(source));
  }
  // Without a fluid source, the first inlet's spacing is the fluid's.
  if (fluid_spacing == 0 && !s.inlets.empty()) fluid_spacing = s.inlets.front().spacing;
  resolve_boundary_spacing(top, s, fluid_spacing);
}

// [[probes]]: each a name and a point or a vertical line. Where a probe may
// be (inside the box, vertical, names unique) is validate()'s.
void read_probes(const Table& top, Scene& s) {
  const Reader& r = top.reader();
  const auto* node = top.find("probes");
  if (!node) return;
  const auto& list = r.array(*node, "probes", "an array of tables ([[probes]])");
  std::vector<std::string_view> known;
  for (const auto& spec : probe_keys()) known.push_back(spec.key);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = fmt::format("probes[{}]", i);
    if (!list[i].is_table()) r.wrong_type(where, "a table", list[i]);
    const Table t(r, list[i].as_table(), where);
    t.only(known, "unknown key for a probe");
    Probe probe;
    for (const auto& spec : probe_keys())
      if (!spec.custom_read) t.read(spec, spec.key, probe);
    if (const auto* line = t.find("line")) {
      const auto& ends = r.array(*line, t.key("line"), "an array of two [x, y, z] points");
      if (ends.size() != 2)
        t.fail("line", fmt::format("expected two points, the lower and the upper end, got {}", ends.size()));
      for (std::size_t k = 0; k < 2; ++k) probe.line.push_back(r.vec3(ends[k], fmt::format("{}[{}]", t.key("line"), k)));
    }
    if (probe.point && !probe.line.empty())
      t.fail("line", fmt::format("cannot be given together with {}: a probe is a point or a line", t.key("point")));
    if (!probe.point && probe.line.empty()) t.need("point", fmt::format(" (give point or {})", t.key("line")));
    s.probes.push_back(std::move(probe));
  }
}

// [[inlets]] and [[outlets]]: tables of declared keys; an inlet's mass is the
// fluid_block's at its spacing. Where they may be is validate()'s.
template <class Item>
std::vector<Item> read_item_list(const Table& top, std::string_view name, std::span<const KeySpec<Item>> keys,
                                 std::string_view noun) {
  const Reader& r = top.reader();
  std::vector<Item> out;
  const auto* node = top.find(name);
  if (!node) return out;
  const auto& list = r.array(*node, name, fmt::format("an array of tables ([[{}]])", name));
  std::vector<std::string_view> known;
  for (const auto& spec : keys) known.push_back(spec.key);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = fmt::format("{}[{}]", name, i);
    if (!list[i].is_table()) r.wrong_type(where, "a table", list[i]);
    const Table t(r, list[i].as_table(), where);
    t.only(known, fmt::format("unknown key for {}", noun));
    Item item;
    for (const auto& spec : keys) t.read(spec, spec.key, item);
    out.push_back(std::move(item));
  }
  return out;
}

void read_inlets_and_outlets(const Table& top, Scene& s) {
  s.inlets = read_item_list<Inlet>(top, "inlets", inlet_keys(), "an inlet");
  s.outlets = read_item_list<Outlet>(top, "outlets", outlet_keys(), "an outlet");
  for (std::size_t i = 0; i < s.inlets.size(); ++i) {
    Inlet& inlet = s.inlets[i];
    if (!s.sph)
      top.fail(fmt::format("inlets[{}]", i), "an inlet emits SPH fluid: the scene needs an [sph] section");
    if (s.sph->smoothing_length / inlet.spacing > 1000)
      top.fail(fmt::format("inlets[{}].spacing", i),
               fmt::format("is over 1000 times smaller than sph.smoothing_length = {}", s.sph->smoothing_length));
    inlet.mass = sph::lattice_mass_for_density(inlet.spacing, s.sph->smoothing_length, s.sph->rest_density,
                                               s.sph->method == sph::SphMethod::Dfsph ? s.sph->kernel
                                                                                      : sph::SphKernel::Thesis);
  }
}

Scene read_scene(const toml::table& root, std::string_view file) {
  const Reader r(file);
  const Table top(r, &root, "");
  Scene s;
  read_format(top, s);
  top.only(known_keys(""), "unknown section");
  s.file = std::string(file);
  // Which solvers the scene has sets some defaults of the keys before them
  // (precision, units); the sections themselves are read below.
  if (top.find("sph")) s.sph.emplace();
  if (top.find("nbody")) s.nbody.emplace();
  read_simulation(top.table("simulation"), s);
  s.sph.reset();
  s.nbody.reset();
  read_sph(top, s);
  read_nbody(top, s);
  if (top.find("random_box")) read_random_box(top, s);
  else if (top.find("box")) read_box(top, s);
  else s.walls = false;  // open space
  const Table forces = top.table("forces");
  forces.only(known_keys("forces"));
  forces.read_scene_keys(s);
  read_output(top.table("output"), s);
  resolve_time_step(top.table("simulation"), s);
  read_inlets_and_outlets(top, s);
  read_particles(top, s);
  read_probes(top, s);
  validate(s);
  return s;
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

// A path segment of digits only; one too large for size_t is out of range anyway.
std::optional<std::size_t> as_index(std::string_view segment) {
  if (segment.empty() || segment.find_first_not_of("0123456789") != std::string_view::npos) return std::nullopt;
  std::size_t index = 0;
  const auto result = std::from_chars(segment.data(), segment.data() + segment.size(), index);
  return result.ec == std::errc{} ? index : std::numeric_limits<std::size_t>::max();
}

void apply_override(toml::table& root, std::string_view text, const Reader& r) {
  const auto equals = text.find('=');
  if (equals == std::string_view::npos) r.fail(fmt::format("--set '{}'", text), "expected key=value");
  const std::string_view key = trim(text.substr(0, equals));
  const std::string_view value_text = trim(text.substr(equals + 1));
  const std::string where = fmt::format("--set {}", key);
  if (key.empty()) r.fail(fmt::format("--set '{}'", text), "empty key");

  std::vector<std::string_view> segments;
  for (std::size_t start = 0;;) {
    const auto dot = key.find('.', start);
    segments.push_back(key.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start));
    if (segments.back().empty()) r.fail(where, "empty segment in the key");
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }

  // The value is TOML, so strings need quotes and arrays brackets, as in the file.
  toml::table parsed;
  try {
    parsed = toml::parse(fmt::format("v = {}", value_text));
  } catch (const toml::parse_error&) {
  }
  if (parsed.size() != 1 || !parsed.get("v"))
    r.fail(where, fmt::format("cannot parse value '{}' (strings need quotes: key=\"text\")", value_text));
  toml::node& value = *parsed.get("v");

  // Walks down tables by name and arrays by index; path names the node reached.
  toml::node* node = &root;
  std::string path;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const std::string_view segment = segments[i];
    const bool last = i + 1 == segments.size();
    const std::string here = path.empty() ? std::string(segment) : fmt::format("{}.{}", path, segment);
    if (auto* array = node->as_array()) {
      const auto index = as_index(segment);
      if (!index) r.fail(where, fmt::format("'{}' is an array; expected an index, got '{}'", path, segment));
      if (*index >= array->size())
        r.fail(where, fmt::format("index {} is out of range: '{}' has {} entries", segment, path, array->size()));
      if (last) array->replace(array->cbegin() + static_cast<std::ptrdiff_t>(*index), std::move(value));
      else node = array->get(*index);
    } else if (auto* table = node->as_table()) {
      if (last) {
        table->insert_or_assign(segment, std::move(value));
      } else if (auto* child = table->get(segment)) {
        node = child;
      } else if (as_index(segments[i + 1])) {
        r.fail(where, fmt::format("index {} is out of range: '{}' is not in the scene", segments[i + 1], here));
      } else {
        node = table->insert(segment, toml::table{}).first->second.as_table();
      }
    } else {
      r.fail(where, fmt::format("'{}' is {}, not a table or an array", path, a_type(*node)));
    }
    path = here;
  }
}

// Through the one guarded reader (io/read_file.hpp): a FIFO or a device is
// refused instead of blocking, and at most kMaxSceneBytes are read.
std::string read_file(const std::filesystem::path& file, const std::string& /*name*/) {
  try {
    return io::read_regular_file(file, io::kMaxSceneBytes);
  } catch (const io::IoError& e) {
    raise(e.what());
  }
}

// The canonical text scene_hash() hashes: every declared key the scene has a
// value for, in declaration order, as a dotted TOML key, then each source as a
// [[particles]] table of its kind's keys; numbers with 17 significant digits
// so that distinct doubles give distinct text.
std::string canonical_text(const Scene& s) {
  std::string out;
  for (const auto& spec : scene_keys())
    if (const auto value = spec.hashed ? spec.get(s) : std::nullopt) {
      const std::string text = value_text(*value, true);
      // unhashed_value is spelt as a scene writes it; a name's text here is quoted.
      const bool old_behaviour = !spec.unhashed_value.empty() &&
                                 (text == spec.unhashed_value || text == fmt::format("\"{}\"", spec.unhashed_value));
      if (old_behaviour) continue;
      out += fmt::format("{} = {}\n", spec.key, text);
    }
  for (const auto& source : s.sources) {
    const SourceKind& kind = kind_of(source);
    out += fmt::format("[[particles]]\nkind = \"{}\"\n", kind.name);
    for (const auto& spec : kind.keys)
      if (const auto value = spec.hashed ? spec.get(source) : std::nullopt)
        out += fmt::format("{} = {}\n", spec.key, value_text(*value, true));
  }
  for (const auto& probe : s.probes) {
    out += "[[probes]]\n";
    for (const auto& spec : probe_keys())
      if (const auto value = spec.get(probe)) out += fmt::format("{} = {}\n", spec.key, value_text(*value, true));
  }
  for (const auto& inlet : s.inlets) {
    out += "[[inlets]]\n";
    for (const auto& spec : inlet_keys())
      if (const auto value = spec.get(inlet)) out += fmt::format("{} = {}\n", spec.key, value_text(*value, true));
  }
  for (const auto& outlet : s.outlets) {
    out += "[[outlets]]\n";
    for (const auto& spec : outlet_keys())
      if (const auto value = spec.get(outlet)) out += fmt::format("{} = {}\n", spec.key, value_text(*value, true));
  }
  return out;
}

}  // namespace

Scene parse_scene(std::string_view text, std::string_view file, std::span<const std::string> overrides) {
  toml::table root;
  try {
    root = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    raise(fmt::format("{}:{}:{}: {}", file, e.source().begin.line, e.source().begin.column, e.description()));
  }
  const Reader r(file);
  for (const auto& o : overrides) apply_override(root, o, r);
  Scene scene = read_scene(root, file);
  // Each snapshot's and mesh's file as resolved (absolute), so that the TOML
  // saved with a run names it from any working directory (read_snapshot_file).
  if (auto* list = root["particles"].as_array(); list && !scene.random_box)
    for (std::size_t i = 0; i < scene.sources.size() && i < list->size(); ++i) {
      auto* table = (*list)[i].as_table();
      if (!table) continue;
      if (const auto* snapshot = std::get_if<SnapshotSource>(&scene.sources[i]))
        table->insert_or_assign("file", snapshot->file);
      const auto* mesh = std::get_if<ObstacleSource>(&scene.sources[i]);
      if (mesh && mesh->shape == ObstacleSource::Shape::Mesh) table->insert_or_assign("file", mesh->file);
      const auto* fill = std::get_if<FluidFillSource>(&scene.sources[i]);
      if (fill && fill->shape == FluidFillSource::Shape::Mesh) table->insert_or_assign("file", fill->file);
    }
  std::ostringstream effective;
  effective << root;
  scene.toml = effective.str();
  return scene;
}

Scene load_scene(const std::filesystem::path& file, std::span<const std::string> overrides) {
  const std::string name = file.string();
  return parse_scene(read_file(file, name), name, overrides);
}

std::uint64_t scene_hash(const Scene& scene) {
  std::uint64_t hash = 0xcbf29ce484222325u;  // FNV-1a 64 offset basis and prime
  for (const char c : canonical_text(scene)) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3u;
  }
  return hash;
}

}  // namespace swirl::scene
