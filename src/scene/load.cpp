#include "swirl/scene/load.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
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

#include "sources.hpp"
#include "swirl/sph/lattice_mass.hpp"

namespace swirl::scene {
namespace {

using Keys = std::span<const std::string_view>;

// The schema: the keys each table may hold. Everything else is refused, with a
// suggestion, so a misspelt optional key cannot silently fall back to its default.
constexpr std::string_view kSections[] = {"simulation", "box",        "forces", "output",
                                          "particles",  "sph",        "random_box", "nbody"};
constexpr std::string_view kNbodyKeys[] = {"method",         "scheme",        "opening", "softening",
                                           "subdomain_size", "subtree_nodes", "tree",    "multipole",
                                           "opening_criterion", "bucket_size", "walk", "group_size"};
constexpr std::string_view kTrees[] = {"paper", "linear"};                 // the order of gravity::Tree
constexpr std::string_view kMultipoles[] = {"monopole", "quadrupole"};     // the order of gravity::Multipole
constexpr std::string_view kCriteria[] = {"paper", "barnes"};              // the order of gravity::Criterion
constexpr std::string_view kWalks[] = {"group", "particle"};               // the order of gravity::Walk
constexpr std::string_view kMethods[] = {"direct", "barnes_hut"};            // the order of gravity::Method
constexpr std::string_view kSchemes[] = {"subdomain", "subtree", "global"};  // the order of gravity::Scheme
constexpr std::string_view kPlummerKeys[] = {"kind", "count", "seed", "mass_cut", "offset", "velocity"};
constexpr std::string_view kUniformSphereKeys[] = {"kind", "count", "seed", "radius", "mass", "offset", "velocity"};
constexpr std::string_view kUniformCubeKeys[] = {"kind", "count", "seed", "side", "mass", "offset", "velocity"};
constexpr std::string_view kColdCollapseKeys[] = {"kind", "count", "seed", "offset", "velocity"};
constexpr std::string_view kCollisionKeys[] = {"kind",      "count",      "seed",     "mass_fraction", "separation",
                                               "impact_parameter", "relative_velocity", "mass_cut", "offset", "velocity"};
constexpr std::string_view kSimulationKeys[] = {"precision", "dt",  "end_time",     "steps",          "block_size",
                                                "dt_max",    "dt_min", "cfl",        "force_factor",   "viscous_factor",
                                                "eta"};
constexpr std::string_view kBoxKeys[] = {"min", "max", "restitution"};
constexpr std::string_view kForcesKeys[] = {"gravity"};
constexpr std::string_view kOutputKeys[] = {"interval", "format"};
constexpr std::string_view kLatticeKeys[] = {"kind", "min", "max", "spacing", "jitter", "seed", "mass", "velocity"};
constexpr std::string_view kRandomKeys[] = {"kind", "min", "max", "count", "seed", "mass", "velocity"};
constexpr std::string_view kListKeys[] = {"kind", "positions", "velocities", "mass", "masses"};
constexpr std::string_view kFluidBlockKeys[] = {"kind", "min", "max", "spacing", "jitter", "seed", "velocity"};
constexpr std::string_view kSphKeys[] = {"smoothing_length", "neighbours", "rest_density",      "sound_speed",
                                         "viscosity",        "pressure",   "negative_pressure", "hash",
                                         "neighbour_search", "grid"};
constexpr std::string_view kHashKeys[] = {"buckets", "duplicate_check"};
constexpr std::string_view kGridKeys[] = {"simd", "cell_order", "skin", "table"};
constexpr std::string_view kCellOrders[] = {"rows", "morton"};  // the order of spatial::CellOrder
constexpr std::string_view kCellTables[] = {"auto", "dense", "hashed"};  // the order of spatial::CellTable
constexpr std::string_view kNeighbourSearches[] = {"grid", "hash"};  // the order of sph::NeighbourSearch
constexpr std::string_view kPressureForms[] = {"thesis", "consistent"};  // the order of sph::PressureForm
constexpr std::string_view kNegativePressures[] = {"keep", "zero"};      // the order of sph::NegativePressure
constexpr std::string_view kRandomBoxKeys[] = {"neighbours", "seed"};
constexpr std::string_view kSourceKeys[] = {
    "kind",     "min",    "max",    "spacing",  "jitter",        "seed",       "mass",
    "velocity", "count",  "positions", "velocities", "masses",   "mass_cut",   "radius",
    "side",     "offset", "mass_fraction", "separation", "impact_parameter", "relative_velocity"};
// A fluid block is a lattice; the last five, from 4 on, are StellarSource models in
// the order of StellarSource::Model.
constexpr std::string_view kKinds[] = {"lattice",        "random",       "list",          "fluid_block", "plummer",
                                       "uniform_sphere", "uniform_cube", "cold_collapse", "plummer_collision"};
constexpr Keys kKindKeys[] = {kLatticeKeys,       kRandomKeys,      kListKeys,         kFluidBlockKeys, kPlummerKeys,
                              kUniformSphereKeys, kUniformCubeKeys, kColdCollapseKeys, kCollisionKeys};
constexpr std::size_t kFirstStellarKind = 4;
constexpr std::string_view kPrecisions[] = {"float", "double"};       // the order of Precision
constexpr std::string_view kFormats[] = {"vtp", "csv"};               // the order of OutputFormat

// Messages are one line by contract, and keys, values and file names come from the user.
[[noreturn]] void raise(std::string message) {
  std::string out;
  for (const char c : message) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      out += fmt::format("\\x{:02x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    else
      out += c;
  }
  throw SceneError(out);
}

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

std::string quoted_list(Keys names) {
  std::string out;
  for (const auto name : names) out += fmt::format("{}'{}'", out.empty() ? "" : ", ", name);
  return out;
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

std::string vec_text(const Vec3d& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }
std::string box_text(const Box<double>& b) { return fmt::format("[{}, {}]", vec_text(b.lo), vec_text(b.hi)); }
std::string count_text(std::uint64_t n) { return n == detail::kSaturated ? "over 1.8e19" : std::to_string(n); }

// An interval a number must lie in, and how to say so.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
  std::string text() const {
    if (std::isinf(hi)) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
    return fmt::format("in {}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
  }
};
constexpr Range kAny{};
constexpr Range kPositive{0, std::numeric_limits<double>::infinity(), true, false};
constexpr Range kNonNegative{0, std::numeric_limits<double>::infinity(), false, false};
constexpr Range kUnit{0, 1, false, false};
constexpr Range kJitter{0, 0.5, false, true};

// Values read from nodes; `where` is the dotted key used in messages.
class Reader {
 public:
  explicit Reader(std::string_view file) : file_(file) {}

  [[noreturn]] void fail(std::string_view where, std::string_view reason) const {
    raise(fmt::format("{}: {}: {}", file_, where, reason));
  }
  [[noreturn]] void wrong_type(std::string_view where, std::string_view expected, const toml::node& node) const {
    fail(where, fmt::format("expected {}, got {}", expected, a_type(node)));
  }

  double number(const toml::node& node, std::string_view where, Range range) const {
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

  Vec3d vec3(const toml::node& node, std::string_view where) const {
    const auto* array = node.as_array();
    if (!array) wrong_type(where, "an array of 3 numbers", node);
    if (array->size() != 3) fail(where, fmt::format("expected an array of 3 numbers, got {} elements", array->size()));
    Vec3d v;
    for (int axis = 0; axis < 3; ++axis)
      v[axis] = number((*array)[static_cast<std::size_t>(axis)], fmt::format("{}[{}]", where, axis), kAny);
    return v;
  }

  std::size_t choice(const toml::node& node, std::string_view where, Keys allowed, std::string_view what) const {
    const auto* s = node.as_string();
    if (!s) wrong_type(where, "a string", node);
    const auto it = std::find(allowed.begin(), allowed.end(), s->get());
    if (it == allowed.end())
      fail(where, fmt::format("unknown {} '{}' (allowed: {})", what, s->get(), quoted_list(allowed)));
    return static_cast<std::size_t>(it - allowed.begin());
  }

  const toml::array& array(const toml::node& node, std::string_view where, std::string_view expected) const {
    const auto* a = node.as_array();
    if (!a) wrong_type(where, expected, node);
    return *a;
  }

  void inside(const Box<double>& box, const Vec3d& p, std::string_view where) const {
    if (!box.contains(p)) fail(where, fmt::format("{} lies outside the box {}", vec_text(p), box_text(box)));
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
  bool reader_has_table() const { return table_ != nullptr; }
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

  double number(std::string_view k, std::optional<double> fallback, Range range = kAny) const {
    if (!find(k) && fallback) return *fallback;
    return r_.number(need(k), key(k), range);
  }

  std::int64_t integer(std::string_view k, std::optional<std::int64_t> fallback, std::int64_t lo,
                       std::int64_t hi = std::numeric_limits<std::int64_t>::max()) const {
    if (!find(k) && fallback) return *fallback;
    const toml::node& node = need(k);
    const auto* i = node.as_integer();
    if (!i) r_.wrong_type(key(k), "an integer", node);
    if (i->get() < lo || i->get() > hi) {
      const bool unbounded = hi == std::numeric_limits<std::int64_t>::max();
      fail(k, unbounded ? fmt::format("must be >= {}, got {}", lo, i->get())
                        : fmt::format("must be in [{}, {}], got {}", lo, hi, i->get()));
    }
    return i->get();
  }

  bool boolean(std::string_view k, bool fallback) const {
    const auto* node = find(k);
    if (!node) return fallback;
    const auto* b = node->as_boolean();
    if (!b) r_.wrong_type(key(k), "a boolean (true or false)", *node);
    return b->get();
  }

  Vec3d vec3(std::string_view k, std::optional<Vec3d> fallback = {}) const {
    if (!find(k) && fallback) return *fallback;
    return r_.vec3(need(k), key(k));
  }

  std::size_t choice(std::string_view k, Keys allowed, std::optional<std::size_t> fallback,
                     std::string_view what) const {
    if (!find(k) && fallback) return *fallback;
    return r_.choice(need(k), key(k), allowed, what);
  }

  // min and max, a valid box; `within` (if given) must contain it.
  Box<double> box(const Box<double>* within) const {
    const Box<double> b{vec3("min"), vec3("max")};
    if (within) {
      r_.inside(*within, b.lo, key("min"));
      r_.inside(*within, b.hi, key("max"));
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (!(b.hi[axis] > b.lo[axis]))
        fail("max", fmt::format("must be greater than {} on every axis, but along {} {} <= {}", key("min"), "xyz"[axis],
                                b.hi[axis], b.lo[axis]));
    }
    return b;
  }

 private:
  const Reader& r_;
  const toml::table* table_;
  std::string path_;
};

void read_simulation(const Table& t, Scene& s) {
  t.only(kSimulationKeys);
  s.precision = static_cast<Precision>(
      t.choice("precision", kPrecisions, static_cast<std::size_t>(s.precision), "precision"));
  // dt: a number, or "adaptive" (then dt_max is the step's cap; see resolve_time_step()).
  const auto* dt_node = t.find("dt");
  s.adaptive_dt = dt_node && dt_node->is_string() && dt_node->value<std::string>() == "adaptive";
  if (!s.adaptive_dt) s.dt = t.number("dt", {}, kPositive);
  const Range fraction{0, 1, true, false};
  const Scene defaults;
  s.cfl = t.number("cfl", defaults.cfl, fraction);
  s.force_factor = t.number("force_factor", defaults.force_factor, fraction);
  s.viscous_factor = t.number("viscous_factor", defaults.viscous_factor, fraction);
  s.eta = t.number("eta", defaults.eta, Range{0, 10, true, false});
  for (const std::string_view k : {"dt_max", "dt_min"})
    if (!s.adaptive_dt && t.find(k)) t.fail(k, fmt::format("needs {} = \"adaptive\" (a fixed dt is the step itself)", t.key("dt")));
  const bool has_end_time = t.find("end_time") != nullptr;
  const bool has_steps = t.find("steps") != nullptr;
  if (has_end_time && has_steps)
    t.fail("steps", fmt::format("cannot be given together with {}; give one of them", t.key("end_time")));
  if (!has_end_time && !has_steps) t.need("end_time", fmt::format(" (give end_time or {})", t.key("steps")));
  if (has_end_time) {
    s.end_time = t.number("end_time", {}, kPositive);
    // total_steps() converts end_time / dt to an integer; it must fit.
    const double ratio = *s.end_time / s.dt;
    if (!s.adaptive_dt && !(ratio <= 0x1p53))
      t.fail("end_time", fmt::format("needs {:.3g} steps of dt = {}, more than the limit of 2^53", ratio, s.dt));
  } else {
    s.steps = static_cast<std::uint64_t>(t.integer("steps", {}, 1));
  }
  s.block_size = static_cast<std::size_t>(t.integer("block_size", 1024, 1));
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
  s.dt = t.number("dt_max", fallback, kPositive);
  s.dt_min = t.number("dt_min", 0.0, kNonNegative);
  if (!(s.dt_min < s.dt)) t.fail("dt_min", fmt::format("must be smaller than {} = {}, got {}", t.key("dt_max"), s.dt, s.dt_min));
}

void read_box(const Table& t, Scene& s) {
  t.only(kBoxKeys);
  s.box = t.box(nullptr);
  s.restitution = t.number("restitution", 0.5, kUnit);
}

void read_output(const Table& t, Scene& s) {
  t.only(kOutputKeys);
  s.output_interval = t.number("interval", 0.0, kNonNegative);
  const auto* node = t.find("format");
  if (!node) return;
  const Reader& r = t.reader();
  const std::string where = t.key("format");
  if (node->is_string()) {
    s.formats = {static_cast<OutputFormat>(r.choice(*node, where, kFormats, "format"))};
    return;
  }
  const auto& list = r.array(*node, where, "a string or an array of strings");
  if (list.empty()) r.fail(where, "must name at least one format");
  s.formats.clear();
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string item = fmt::format("{}[{}]", where, i);
    const auto format = static_cast<OutputFormat>(r.choice(list[i], item, kFormats, "format"));
    if (std::find(s.formats.begin(), s.formats.end(), format) != s.formats.end())
      r.fail(item, fmt::format("'{}' is listed twice", kFormats[static_cast<std::size_t>(format)]));
    s.formats.push_back(format);
  }
}

std::uint64_t read_seed(const Table& t) { return static_cast<std::uint64_t>(t.integer("seed", 1, 0)); }

// A lattice; a fluid block (fluid = true) takes its mass from [sph].
LatticeSource read_lattice(const Table& t, const Scene& s, bool fluid) {
  LatticeSource src;
  src.region = t.box(s.walls ? &s.box : nullptr);
  src.spacing = t.number("spacing", {}, kPositive);
  src.jitter = t.number("jitter", 0.0, kJitter);
  src.seed = read_seed(t);
  if (fluid) {
    if (!s.sph) t.fail("kind", "a 'fluid_block' needs an [sph] section (its mass comes from sph.rest_density)");
    if (s.sph->smoothing_length / src.spacing > 1000)
      t.fail("spacing", fmt::format("is over 1000 times smaller than sph.smoothing_length = {}", s.sph->smoothing_length));
    src.mass = sph::lattice_mass_for_density(src.spacing, s.sph->smoothing_length, s.sph->rest_density);
  } else {
    src.mass = t.number("mass", {}, kPositive);
  }
  src.velocity = t.vec3("velocity", Vec3d{});
  const auto n = detail::lattice_counts(src);
  for (int axis = 0; axis < 3; ++axis) {
    if (n[static_cast<std::size_t>(axis)] != 0) continue;
    t.reader().fail(t.path(), fmt::format("makes no particles: the region is {} long along {}, less than the spacing {}",
                                          src.region.extent()[axis], "xyz"[axis], src.spacing));
  }
  return src;
}

RandomSource read_random(const Table& t, const Scene& s) {
  RandomSource src;
  src.region = t.box(s.walls ? &s.box : nullptr);
  src.count = static_cast<std::size_t>(t.integer("count", {}, 1, static_cast<std::int64_t>(detail::kMaxParticles)));
  src.seed = read_seed(t);
  src.mass = t.number("mass", {}, kPositive);
  src.velocity = t.vec3("velocity", Vec3d{});
  return src;
}

ListSource read_list(const Table& t, const Scene& s) {
  const Reader& r = t.reader();
  ListSource src;
  const std::string where = t.key("positions");
  const auto& positions = r.array(t.need("positions"), where, "an array of [x, y, z] positions");
  if (positions.empty()) r.fail(where, "must list at least one position");
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const std::string item = fmt::format("{}[{}]", where, i);
    src.positions.push_back(r.vec3(positions[i], item));
    if (s.walls) r.inside(s.box, src.positions.back(), item);
  }
  // Per-particle arrays must match positions one to one.
  auto per_particle = [&](std::string_view k, std::string_view expected) -> const toml::array& {
    const auto& list = r.array(*t.find(k), t.key(k), expected);
    if (list.size() != positions.size())
      t.fail(k, fmt::format("has {} entries but {} has {}", list.size(), where, positions.size()));
    return list;
  };
  if (t.find("velocities")) {
    const auto& velocities = per_particle("velocities", "an array of [vx, vy, vz] velocities");
    for (std::size_t i = 0; i < velocities.size(); ++i)
      src.velocities.push_back(r.vec3(velocities[i], fmt::format("{}[{}]", t.key("velocities"), i)));
  }
  const bool has_mass = t.find("mass") != nullptr;
  const bool has_masses = t.find("masses") != nullptr;
  if (has_mass && has_masses)
    t.fail("masses", fmt::format("cannot be given together with {}; give one of them", t.key("mass")));
  if (has_mass) {
    src.masses.assign(positions.size(), t.number("mass", {}, kPositive));
  } else if (has_masses) {
    const auto& masses = per_particle("masses", "an array of numbers");
    for (std::size_t i = 0; i < masses.size(); ++i)
      src.masses.push_back(r.number(masses[i], fmt::format("{}[{}]", t.key("masses"), i), kPositive));
  } else {
    t.need("mass", fmt::format(" (give mass, or {} with one per position)", t.key("masses")));
  }
  return src;
}

// The self-gravitating models (kinds from kFirstStellarKind on).
StellarSource read_stellar(const Table& t, const Scene& s, std::size_t kind) {
  using Model = StellarSource::Model;
  if (s.walls) t.fail("kind", fmt::format("'{}' is a self-gravitating model: it needs open space (no [box])", kKinds[kind]));
  StellarSource src;
  src.model = static_cast<Model>(kind - kFirstStellarKind);
  src.count = static_cast<std::size_t>(t.integer("count", {}, 1, static_cast<std::int64_t>(detail::kMaxParticles)));
  src.seed = read_seed(t);
  src.offset = t.vec3("offset", Vec3d{});
  src.velocity = t.vec3("velocity", Vec3d{});
  const Range cut{0, 1, true, false};
  switch (src.model) {
    case Model::Plummer: src.plummer.mass_cut = t.number("mass_cut", 0.999, cut); break;
    case Model::UniformSphere:
      src.size = t.number("radius", 1.0, kPositive);
      src.mass = t.number("mass", 1.0, kPositive);
      break;
    case Model::UniformCube:
      src.size = t.number("side", 1.0, kPositive);
      src.mass = t.number("mass", 1.0, kPositive);
      break;
    case Model::ColdCollapse: break;
    case Model::PlummerCollision: {
      auto& c = src.collision;
      if (src.count < 2) t.fail("count", "a collision needs at least 2 particles");
      c.mass_fraction = t.number("mass_fraction", 0.5, Range{0, 1, true, true});
      c.separation = t.number("separation", 10.0, kPositive);
      c.impact_parameter = t.number("impact_parameter", std::min(2.0, 0.2 * c.separation), Range{0, c.separation, false, true});
      // Each sphere needs a particle, and the geometry (d², the parabolic speed √(2/d)) must stay finite.
      const double n1 = std::round(c.mass_fraction * static_cast<double>(src.count));
      if (n1 < 1 || n1 > static_cast<double>(src.count) - 1)
        t.fail("mass_fraction", fmt::format("{} of {} particles leaves one sphere empty", c.mass_fraction, src.count));
      if (!std::isfinite(c.separation * c.separation) || !std::isfinite(std::sqrt(2.0 / c.separation)))
        t.fail("separation", fmt::format("{} is out of the usable range", c.separation));
      if (t.find("relative_velocity")) c.relative_velocity = t.number("relative_velocity", {}, kNonNegative);
      c.mass_cut = t.number("mass_cut", 0.999, cut);
      break;
    }
  }
  return src;
}

void read_particles(const Table& top, Scene& s) {
  const Reader& r = top.reader();
  if (s.random_box) return;  // its one source was made by read_random_box()
  const auto* node = top.find("particles");
  if (!node) r.fail("particles", "no particles: the scene needs at least one [[particles]] source");
  const auto& list = r.array(*node, "particles", "an array of tables ([[particles]])");
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = fmt::format("particles[{}]", i);
    if (!list[i].is_table()) r.wrong_type(where, "a table", list[i]);
    const Table t(r, list[i].as_table(), where);
    t.only(kSourceKeys);  // first, so that a misspelt "kind" is reported as such
    const std::size_t kind = t.choice("kind", kKinds, {}, "kind");
    t.only(kKindKeys[kind], fmt::format("unknown key for kind '{}'", kKinds[kind]));
    if (kind == 0 || kind == 3) s.sources.emplace_back(read_lattice(t, s, kind == 3));
    else if (kind == 1) s.sources.emplace_back(read_random(t, s));
    else if (kind == 2) s.sources.emplace_back(read_list(t, s));
    else s.sources.emplace_back(read_stellar(t, s, kind));
    const std::uint64_t n = detail::source_count(s.sources.back());
    if (n > detail::kMaxParticles)
      r.fail(where, fmt::format("makes {} particles, more than the limit of {} (2^31); is the spacing too small?",
                                count_text(n), detail::kMaxParticles));
    total = detail::add_sat(total, n);
  }
  if (total == 0) r.fail("particles", "no particles: the scene needs at least one [[particles]] source");
  if (total > detail::kMaxParticles)
    r.fail("particles", fmt::format("the sources make {} particles in total, more than the limit of {} (2^31)",
                                    count_text(total), detail::kMaxParticles));
}

// [sph]. The smoothing length is given, or derived from a neighbour count and
// the spacing of the first fluid block (volume per particle = spacing³).
void read_sph(const Table& top, Scene& s) {
  const Table t = top.table("sph");
  if (!top.find("sph")) return;
  t.only(kSphKeys);
  sph::SphParameters p;
  p.rest_density = t.number("rest_density", 1000.0, kPositive);
  p.sound_speed = t.number("sound_speed", 10.0, kPositive);
  p.viscosity = t.number("viscosity", 0.1, kNonNegative);
  p.pressure_form = static_cast<sph::PressureForm>(t.choice("pressure", kPressureForms, 0, "pressure form"));
  p.negative_pressure =
      static_cast<sph::NegativePressure>(t.choice("negative_pressure", kNegativePressures, 0, "negative pressure rule"));
  const Table hash = t.table("hash");
  hash.only(kHashKeys);
  p.buckets = static_cast<std::uint32_t>(hash.integer("buckets", 0, 0, 0xffffffffLL));
  p.duplicate_check = hash.boolean("duplicate_check", true);
  p.neighbour_search =
      static_cast<sph::NeighbourSearch>(t.choice("neighbour_search", kNeighbourSearches, 0, "neighbour search"));
  const Table grid = t.table("grid");
  grid.only(kGridKeys);
  p.simd = grid.boolean("simd", true);
  p.cell_order = static_cast<spatial::CellOrder>(grid.choice("cell_order", kCellOrders, 0, "cell order"));
  // A skin beyond 1e9 m is a typo (as for h).
  p.grid_skin = grid.number("skin", 0.0, Range{0, 1e9, false, false});
  p.cell_table = static_cast<spatial::CellTable>(grid.choice("table", kCellTables, 0, "cell table"));
  const bool has_h = t.find("smoothing_length") != nullptr, has_k = t.find("neighbours") != nullptr;
  if (has_h && has_k) t.fail("neighbours", fmt::format("cannot be given together with {}", t.key("smoothing_length")));
  if (has_h) {
    // A support radius beyond 1e9 m is a typo; it would also overflow h³.
    p.smoothing_length = t.number("smoothing_length", {}, Range{0, 1e9, true, false});
  } else {
    const double k = t.number("neighbours", {}, Range{0, 10000, true, false});
    // The spacing of the first fluid block sets the volume per particle.
    const auto* list = top.find("particles") ? top.find("particles")->as_array() : nullptr;
    const toml::node* spacing = nullptr;
    for (std::size_t i = 0; list && i < list->size() && !spacing; ++i) {
      const auto* src = (*list)[i].as_table();
      const auto* kind = src ? src->get("kind") : nullptr;
      if (kind && kind->value<std::string>() == "fluid_block") spacing = src->get("spacing");
    }
    if (!spacing)
      t.fail("neighbours", fmt::format("needs a [[particles]] source of kind 'fluid_block' to size h from "
                                       "(or give {})", t.key("smoothing_length")));
    const double s0 = t.reader().number(*spacing, "particles[].spacing", kPositive);
    p.smoothing_length = sph::smoothing_length_for_neighbors(k, s0 * s0 * s0);
  }
  s.sph = p;
}

// [nbody]: self-gravity.
void read_nbody(const Table& t, Scene& s) {
  if (!t.reader_has_table()) return;
  t.only(kNbodyKeys);
  gravity::GravitySettings g;
  g.method = static_cast<gravity::Method>(t.choice("method", kMethods, 1, "method"));
  g.scheme = static_cast<gravity::Scheme>(t.choice("scheme", kSchemes, 2, "scheme"));
  g.opening = t.number("opening", 0.5, kUnit);
  g.softening = t.number("softening", 0.01, kNonNegative);
  g.subdomain_size = static_cast<std::size_t>(t.integer("subdomain_size", 208, 1));
  g.subtree_nodes = static_cast<std::size_t>(t.integer("subtree_nodes", 370, 1));
  // The paper's schemes walk the paper's tree; only `global` can take the
  // linear one, and only the linear tree has multipoles and Barnes' rule.
  const bool global = g.scheme == gravity::Scheme::global;
  g.tree = static_cast<gravity::Tree>(t.choice("tree", kTrees, global ? 1 : 0, "tree"));
  if (g.tree == gravity::Tree::linear && !global)
    t.fail("tree", fmt::format("\"linear\" needs {} = \"global\" (the paper's scheme \"{}\" walks the paper's tree)",
                               t.key("scheme"), kSchemes[static_cast<std::size_t>(g.scheme)]));
  const bool linear = g.tree == gravity::Tree::linear;
  g.multipole = static_cast<gravity::Multipole>(t.choice("multipole", kMultipoles, linear ? 1 : 0, "multipole"));
  g.criterion = static_cast<gravity::Criterion>(t.choice("opening_criterion", kCriteria, linear ? 1 : 0, "opening criterion"));
  if (!linear && g.multipole != gravity::Multipole::monopole)
    t.fail("multipole", "the paper's tree is monopole only (use tree = \"linear\" with scheme = \"global\")");
  if (!linear && g.criterion != gravity::Criterion::paper)
    t.fail("opening_criterion", "the paper's tree uses the paper's rule only (use tree = \"linear\" with scheme = \"global\")");
  g.bucket_size = static_cast<std::size_t>(t.integer("bucket_size", 16, 1, 1 << 20));
  g.walk = static_cast<gravity::Walk>(t.choice("walk", kWalks, linear ? 0 : 1, "walk"));
  if (!linear && g.walk != gravity::Walk::particle)
    t.fail("walk", "the paper's tree walks per particle only (use tree = \"linear\" with scheme = \"global\")");
  g.group_size = static_cast<std::size_t>(t.integer("group_size", 256, 1, 1 << 20));
  s.nbody = g;
}

// [random_box] with the root key `particles` = N: the thesis's section 5 set-up.
void read_random_box(const Table& top, Scene& s) {
  if (!top.find("random_box")) return;
  const Table t = top.table("random_box");
  t.only(kRandomBoxKeys);
  if (!s.sph) t.fail("neighbours", "a random box is sized from sph.smoothing_length: add an [sph] section");
  if (top.table("box").find("min") || top.table("box").find("max"))
    top.fail("box", "min and max are derived from the random box (L³ = N·(4/3)π h³ / k); remove them");
  Scene::RandomBox rb;
  rb.particles = static_cast<std::uint64_t>(
      top.integer("particles", {}, 1, static_cast<std::int64_t>(detail::kMaxParticles)));
  rb.neighbors = t.number("neighbours", 25.0, Range{0, 10000, true, false});
  rb.seed = static_cast<std::uint64_t>(t.integer("seed", 1, 0));
  const double h = s.sph->smoothing_length;
  const double side =
      std::cbrt(static_cast<double>(rb.particles) * 4.0 / 3.0 * std::numbers::pi * h * h * h / rb.neighbors);
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
                                     h, s.sph->rest_density, rb.neighbors, side, src.mass));
  s.sources.emplace_back(src);
  s.random_box = rb;
}

Scene read_scene(const toml::table& root, std::string_view file) {
  const Reader r(file);
  const Table top(r, &root, "");
  top.only(kSections, "unknown section");
  Scene s;
  s.file = std::string(file);
  // Self-gravity defaults to double precision, fluids to float.
  s.precision = top.find("nbody") ? Precision::Double : Precision::Float;
  read_simulation(top.table("simulation"), s);
  read_sph(top, s);
  read_nbody(top.table("nbody"), s);
  if (!top.find("box") && !top.find("random_box")) {
    s.walls = false;  // open space
  } else if (top.find("random_box")) {
    const Table box = top.table("box");
    box.only(kBoxKeys);
    s.restitution = box.number("restitution", 0.5, kUnit);
    read_random_box(top, s);
  } else {
    read_box(top.table("box"), s);
  }
  const Table forces = top.table("forces");
  forces.only(kForcesKeys);
  // A self-gravitating system floats in open space unless told otherwise.
  s.gravity = forces.vec3("gravity", s.nbody ? Vec3d{} : s.gravity);
  read_output(top.table("output"), s);
  resolve_time_step(top.table("simulation"), s);
  read_particles(top, s);
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

std::string read_file(const std::filesystem::path& file, const std::string& name) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(file.c_str(), "rb"), &std::fclose);
  if (!f) raise(fmt::format("{}: cannot read: {}", name, std::strerror(errno)));
  std::string text;
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f.get())) > 0) text.append(buffer, n);
  if (std::ferror(f.get())) raise(fmt::format("{}: cannot read: {}", name, std::strerror(errno)));
  return text;
}

// The canonical text scene_hash() hashes: every field, in a fixed order, numbers
// with 17 significant digits so that distinct doubles give distinct text.
std::string canonical_text(const Scene& s) {
  fmt::memory_buffer out;
  auto put = [&]<class... Args>(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(out), format, std::forward<Args>(args)...);
  };
  auto vec = [](const Vec3d& v) { return fmt::format("[{:.17g}, {:.17g}, {:.17g}]", v.x, v.y, v.z); };
  put("[simulation]\nprecision = \"{}\"\ndt = {:.17g}\n", kPrecisions[static_cast<std::size_t>(s.precision)], s.dt);
  if (s.end_time) put("end_time = {:.17g}\n", *s.end_time);
  if (s.steps) put("steps = {}\n", *s.steps);
  put("block_size = {}\n", s.block_size);
  // Time-step control, only when it differs from a fixed dt with the default
  // conditions, so that older scenes keep their hash.
  const Scene defaults;
  if (s.adaptive_dt || s.cfl != defaults.cfl || s.force_factor != defaults.force_factor ||
      s.viscous_factor != defaults.viscous_factor || s.eta != defaults.eta)
    put("adaptive = {}\ndt_min = {:.17g}\ncfl = {:.17g}\nforce_factor = {:.17g}\nviscous_factor = {:.17g}\neta = {:.17g}\n",
        s.adaptive_dt, s.dt_min, s.cfl, s.force_factor, s.viscous_factor, s.eta);
  if (s.walls) put("[box]\nmin = {}\nmax = {}\nrestitution = {:.17g}\n", vec(s.box.lo), vec(s.box.hi), s.restitution);
  put("[forces]\ngravity = {}\n", vec(s.gravity));
  put("[output]\ninterval = {:.17g}\nformat = [", s.output_interval);
  for (std::size_t i = 0; i < s.formats.size(); ++i)
    put("{}\"{}\"", i ? ", " : "", kFormats[static_cast<std::size_t>(s.formats[i])]);
  put("]\n");
  if (s.sph) {
    put("[sph]\nsmoothing_length = {:.17g}\nrest_density = {:.17g}\nsound_speed = {:.17g}\nviscosity = {:.17g}\n",
        s.sph->smoothing_length, s.sph->rest_density, s.sph->sound_speed, s.sph->viscosity);
    put("pressure = \"{}\"\nnegative_pressure = \"{}\"\nhash = {{ buckets = {}, duplicate_check = {} }}\n",
        kPressureForms[static_cast<std::size_t>(s.sph->pressure_form)],
        kNegativePressures[static_cast<std::size_t>(s.sph->negative_pressure)], s.sph->buckets,
        s.sph->duplicate_check);
    put("neighbour_search = \"{}\"\ngrid = {{ simd = {}, cell_order = \"{}\", skin = {:.17g}, table = \"{}\" }}\n",
        kNeighbourSearches[static_cast<std::size_t>(s.sph->neighbour_search)], s.sph->simd,
        kCellOrders[static_cast<std::size_t>(s.sph->cell_order)], s.sph->grid_skin,
        kCellTables[static_cast<std::size_t>(s.sph->cell_table)]);
  }
  if (s.nbody)
    put("[nbody]\nmethod = \"{}\"\nscheme = \"{}\"\nopening = {:.17g}\nsoftening = {:.17g}\nsubdomain_size = {}\n"
        "subtree_nodes = {}\n",
        kMethods[static_cast<std::size_t>(s.nbody->method)], kSchemes[static_cast<std::size_t>(s.nbody->scheme)],
        s.nbody->opening, s.nbody->softening, s.nbody->subdomain_size, s.nbody->subtree_nodes);
  if (s.nbody)
    put("tree = \"{}\"\nmultipole = \"{}\"\nopening_criterion = \"{}\"\nbucket_size = {}\nwalk = \"{}\"\ngroup_size = {}\n",
        kTrees[static_cast<std::size_t>(s.nbody->tree)], kMultipoles[static_cast<std::size_t>(s.nbody->multipole)],
        kCriteria[static_cast<std::size_t>(s.nbody->criterion)], s.nbody->bucket_size,
        kWalks[static_cast<std::size_t>(s.nbody->walk)], s.nbody->group_size);
  if (s.random_box)
    put("[random_box]\nparticles = {}\nneighbours = {:.17g}\nseed = {}\n", s.random_box->particles,
        s.random_box->neighbors, s.random_box->seed);
  for (const auto& source : s.sources) {
    if (const auto* l = std::get_if<LatticeSource>(&source)) {
      put("[[particles]]\nkind = \"lattice\"\nmin = {}\nmax = {}\nspacing = {:.17g}\njitter = {:.17g}\nseed = {}\n",
          vec(l->region.lo), vec(l->region.hi), l->spacing, l->jitter, l->seed);
      put("mass = {:.17g}\nvelocity = {}\n", l->mass, vec(l->velocity));
    } else if (const auto* q = std::get_if<RandomSource>(&source)) {
      put("[[particles]]\nkind = \"random\"\nmin = {}\nmax = {}\ncount = {}\nseed = {}\n", vec(q->region.lo),
          vec(q->region.hi), q->count, q->seed);
      put("mass = {:.17g}\nvelocity = {}\n", q->mass, vec(q->velocity));
    } else if (const auto* m = std::get_if<StellarSource>(&source)) {
      put("[[particles]]\nkind = \"{}\"\ncount = {}\nseed = {}\nsize = {:.17g}\nmass = {:.17g}\noffset = {}\n",
          kKinds[kFirstStellarKind + static_cast<std::size_t>(m->model)], m->count, m->seed, m->size, m->mass,
          vec(m->offset));
      put("velocity = {}\nmass_cut = {:.17g}\ncollision = [{:.17g}, {:.17g}, {:.17g}, {:.17g}, {:.17g}]\n",
          vec(m->velocity), m->plummer.mass_cut, m->collision.mass_fraction, m->collision.separation,
          m->collision.impact_parameter, m->collision.relative_velocity.value_or(-1.0), m->collision.mass_cut);
    } else {
      const auto& list = std::get<ListSource>(source);
      put("[[particles]]\nkind = \"list\"\npositions = [");
      for (std::size_t i = 0; i < list.positions.size(); ++i) put("{}{}", i ? ", " : "", vec(list.positions[i]));
      put("]\nvelocities = [");
      for (std::size_t i = 0; i < list.velocities.size(); ++i) put("{}{}", i ? ", " : "", vec(list.velocities[i]));
      put("]\nmasses = [");
      for (std::size_t i = 0; i < list.masses.size(); ++i) put("{}{:.17g}", i ? ", " : "", list.masses[i]);
      put("]\n");
    }
  }
  return fmt::to_string(out);
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
