// The scene schema: every key a scene file may hold, declared once.
//
// Each KeySpec gives a key's dotted name, type, unit, allowed range or names,
// one line of documentation, and how to read and write the typed field it
// fills. Everything else is derived from these declarations: the TOML reader
// (scene/load.hpp) with its unknown-key check and "did you mean" suggestion,
// validate() (scene/validate.hpp), the canonical text scene_hash() hashes, and
// the key tables of docs/scenes.md (key_table_markdown()).
//
// Defaults are the member initialisers of Scene, sph::SphParameters,
// gravity::GravitySettings and the source structs: a key absent from a file
// keeps its field's default, and the docs print that same value. A few
// defaults depend on other keys (precision on [nbody], tree on scheme, ...);
// those keys say so in `default_doc`, and the reader applies the rule.
//
// Enum names come from the one table next to each enum (kSchemeNames, ...).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "swirl/core/vec3.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// An interval a number (or every element of a list of numbers) must lie in.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
  bool unbounded() const { return std::isinf(lo) && std::isinf(hi); }
  // "> 0", ">= 1", "in [0, 1)"; "" when unbounded.
  std::string text() const;
};

// What a key holds, in file terms. Vectors are arrays of exactly 3 numbers.
// A Name is one of a list; a Text is any non-empty string (a path).
enum class KeyType { Number, Integer, Boolean, Name, NameList, Vector, VectorList, NumberList, Text };

// A key's value, whatever its type: Number → double, Integer → uint64_t,
// Boolean → bool, Name → string_view (one of the key's names), NameList →
// vector<string_view>, Vector → Vec3d, VectorList → vector<Vec3d>,
// NumberList → vector<double>, Text → string_view (into the owner's
// std::string, or the TOML node read: valid while that lives).
using KeyValue = std::variant<double, std::uint64_t, bool, std::string_view, Vec3d, std::vector<std::string_view>,
                              std::vector<Vec3d>, std::vector<double>>;

// One key. Owner is Scene (sections) or ParticleSource ([[particles]] keys).
template <class Owner>
struct KeySpec {
  std::string_view key{};      // as written in a file, dotted from its table: "simulation.dt", "sph.grid.skin";
                             // for [[particles]], the key within one source: "spacing"
  std::string_view section{};  // the docs table it is listed in: "simulation", "sph", "random_box", a kind
  KeyType type = KeyType::Number;
  std::string_view unit{};     // "s", "m/s²"; "" for none
  Range range{};               // Number, Integer, NumberList
  std::vector<std::string_view> names{};  // Name, NameList: the allowed names, in the enum table's order
  std::string_view noun{};     // Name, NameList: what a name names, for "unknown <noun> 'x'"
  std::string_view doc{};      // one line for docs/scenes.md
  bool required = false;     // a file without it is refused
  std::string_view default_doc{};  // the docs' default when it is not simply the field's default value
  std::string_view type_doc{};     // the docs' type when it is not simply `type`'s
  // Read by hand in src/scene/load.cpp (its value depends on other keys or
  // takes two forms) rather than by the generic reader; still declared here
  // for the unknown-key check, validation, the hash and the docs.
  bool custom_read = false;
  bool hashed = true;        // false only for keys that cannot change a run's results
  // A key added after checkpoints existed: its value is left out of the hash
  // when it is this one (the behaviour from before the key), so that those
  // checkpoints keep their hash while any other value changes it.
  std::string_view unhashed_value{};
  // The typed field's value; nullopt when the owner has none (its section or
  // optional field is absent, or the key names no field of its own).
  std::function<std::optional<KeyValue>(const Owner&)> get{};
  // Stores a value of the key's type (already checked); empty for keys without a field.
  std::function<void(Owner&, const KeyValue&)> set{};
  // For a key whose default depends on keys read before it: that default.
  std::function<std::optional<KeyValue>(const Owner&)> context_default{};
};

// A [[particles]] kind: its name and the keys a source of that kind may hold
// (besides `kind`). A "fluid_block" is stored as a LatticeSource.
struct SourceKind {
  std::string_view name{};
  std::string_view doc{};
  std::vector<KeySpec<ParticleSource>> keys{};
  ParticleSource prototype{};  // a source of this kind with every default
};

// Every section key, in the order of docs/scenes.md and of the scene hash's text.
std::span<const KeySpec<Scene>> scene_keys();

// The keys of one [[probes]] table.
std::span<const KeySpec<Probe>> probe_keys();

// The keys of one [[inlets]] table, and of one [[outlets]] table.
std::span<const KeySpec<Inlet>> inlet_keys();
std::span<const KeySpec<Outlet>> outlet_keys();

// The section tables, in order ("" is the root); `particles` is the array of
// sources, `probes` the array of probes, `inlets` and `outlets` theirs.
std::span<const std::string_view> scene_sections();

// Every kind of [[particles]] source, in the order of the `kind` names.
std::span<const SourceKind> source_kinds();

// The kind a source is written as (a fluid block is a "lattice": its mass is
// resolved), and that kind's declaration.
const SourceKind& kind_of(const ParticleSource& source);

// `value` as TOML: numbers with 17 significant digits when `exact`, else the
// shortest text that reads back the same; strings as basic strings, with `"`,
// `\` and control characters escaped.
std::string value_text(const KeyValue& value, bool exact);

// The docs' key table of one section ("simulation", "sph", ..., "particles"
// for `kind`, or a kind's name), in Markdown, from the declarations above.
std::string key_table_markdown(std::string_view section);

// Every section key_table_markdown() knows, in docs order.
std::vector<std::string_view> key_table_sections();

// `markdown` (docs/scenes.md) with the body of every generated region,
//   <!-- scene-keys:SECTION (generated by scene_keys_doc; do not edit) -->
//   ...
//   <!-- /scene-keys -->
// replaced by key_table_markdown(SECTION). Throws std::runtime_error naming a
// section without a region, an unknown section or an unclosed region.
std::string with_generated_key_tables(std::string_view markdown);

}  // namespace swirl::scene
