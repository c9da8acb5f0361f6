// The declaration of every scene key (scene/keys.hpp), and the docs' key
// tables made from it.
#include "swirl/scene/keys.hpp"

#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

#include "sources.hpp"

namespace swirl::scene {

std::string Range::text() const {
  if (unbounded()) return {};
  if (std::isinf(hi)) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
  if (std::isinf(lo)) return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
  return fmt::format("in {}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
}

namespace {

// ---- From typed fields to KeyValue and back ---------------------------------

// The name tables, found by the enum's type.
constexpr std::span<const EnumName<Precision>> names_of(Precision) { return kPrecisionNames; }
constexpr std::span<const EnumName<Units>> names_of(Units) { return kUnitsNames; }
constexpr std::span<const EnumName<SurfaceFormat>> names_of(SurfaceFormat) { return kSurfaceFormatNames; }
constexpr std::span<const EnumName<TimeSteps>> names_of(TimeSteps) { return kTimeStepsNames; }
constexpr std::span<const EnumName<Walls>> names_of(Walls) { return kWallsNames; }
constexpr std::span<const EnumName<boundary::RigidMotion::Kind>> names_of(boundary::RigidMotion::Kind) {
  return boundary::kRigidMotionNames;
}
constexpr std::span<const EnumName<OutputFormat>> names_of(OutputFormat) { return kOutputFormatNames; }
constexpr std::span<const EnumName<sph::PressureForm>> names_of(sph::PressureForm) { return sph::kPressureFormNames; }
constexpr std::span<const EnumName<sph::NegativePressure>> names_of(sph::NegativePressure) {
  return sph::kNegativePressureNames;
}
constexpr std::span<const EnumName<sph::NeighbourSearch>> names_of(sph::NeighbourSearch) {
  return sph::kNeighbourSearchNames;
}
constexpr std::span<const EnumName<sph::SphMethod>> names_of(sph::SphMethod) { return sph::kSphMethodNames; }
constexpr std::span<const EnumName<sph::SphKernel>> names_of(sph::SphKernel) { return sph::kSphKernelNames; }
constexpr std::span<const EnumName<spatial::CellOrder>> names_of(spatial::CellOrder) { return spatial::kCellOrderNames; }
constexpr std::span<const EnumName<spatial::DuplicateCheck>> names_of(spatial::DuplicateCheck) {
  return spatial::kCheckPlacementNames;
}
constexpr std::span<const EnumName<spatial::TableBuild>> names_of(spatial::TableBuild) {
  return spatial::kTableBuildNames;
}
constexpr std::span<const EnumName<spatial::NeighbourHashes>> names_of(spatial::NeighbourHashes) {
  return spatial::kNeighbourHashesNames;
}
constexpr std::span<const EnumName<spatial::CellTable>> names_of(spatial::CellTable) { return spatial::kCellTableNames; }
constexpr std::span<const EnumName<gravity::Method>> names_of(gravity::Method) { return gravity::kMethodNames; }
constexpr std::span<const EnumName<gravity::Scheme>> names_of(gravity::Scheme) { return gravity::kSchemeNames; }
constexpr std::span<const EnumName<gravity::Tree>> names_of(gravity::Tree) { return gravity::kTreeNames; }
constexpr std::span<const EnumName<gravity::Multipole>> names_of(gravity::Multipole) { return gravity::kMultipoleNames; }
constexpr std::span<const EnumName<gravity::Criterion>> names_of(gravity::Criterion) { return gravity::kCriterionNames; }
constexpr std::span<const EnumName<gravity::Walk>> names_of(gravity::Walk) { return gravity::kWalkNames; }
constexpr std::span<const EnumName<gravity::SubdomainSplit>> names_of(gravity::SubdomainSplit) {
  return gravity::kSubdomainSplitNames;
}
constexpr std::span<const EnumName<gravity::SubtreeSplit>> names_of(gravity::SubtreeSplit) {
  return gravity::kSubtreeSplitNames;
}
constexpr std::span<const EnumName<gravity::UpperNodes>> names_of(gravity::UpperNodes) {
  return gravity::kUpperNodesNames;
}

template <class T>
concept NamedEnum = std::is_enum_v<T> && requires(T v) { names_of(v); };
template <class T>
concept Count = std::is_integral_v<T> && std::is_unsigned_v<T> && !std::is_same_v<T, bool>;

// A std::vector of a named enum: a NameList key.
template <class T>
concept EnumList = requires { typename T::value_type; } && NamedEnum<typename T::value_type>;

template <class T>
struct OptionalOf {};
template <class T>
struct OptionalOf<std::optional<T>> {
  using type = T;
};
template <class T>
concept Optional = requires { typename OptionalOf<T>::type; };

template <NamedEnum E>
std::vector<std::string_view> name_list() {
  std::vector<std::string_view> out;
  for (const auto& entry : names_of(E{})) out.push_back(entry.name);
  return out;
}

// The key type a field of type T has, and its names when it holds enums.
template <class T>
constexpr KeyType key_type() {
  if constexpr (Optional<T>) return key_type<typename OptionalOf<T>::type>();
  else if constexpr (std::is_same_v<T, double>) return KeyType::Number;
  else if constexpr (std::is_same_v<T, bool>) return KeyType::Boolean;
  else if constexpr (Count<T>) return KeyType::Integer;
  else if constexpr (NamedEnum<T>) return KeyType::Name;
  else if constexpr (std::is_same_v<T, Vec3d>) return KeyType::Vector;
  else if constexpr (std::is_same_v<T, std::vector<Vec3d>>) return KeyType::VectorList;
  else if constexpr (std::is_same_v<T, std::vector<double>>) return KeyType::NumberList;
  else if constexpr (std::is_same_v<T, std::string>) return KeyType::Text;
  else return KeyType::NameList;  // std::vector of a named enum
}

template <class T>
std::vector<std::string_view> names_for() {
  if constexpr (Optional<T>) return names_for<typename OptionalOf<T>::type>();
  else if constexpr (NamedEnum<T>) return name_list<T>();
  else if constexpr (EnumList<T>)
    return name_list<typename T::value_type>();
  else return {};
}

template <class T>
std::optional<KeyValue> to_value(const T& v) {
  if constexpr (Optional<T>) {
    if (!v) return std::nullopt;
    return to_value(*v);
  } else if constexpr (Count<T>) {
    return KeyValue{static_cast<std::uint64_t>(v)};
  } else if constexpr (NamedEnum<T>) {
    // An enum cast from an out-of-range integer has no name; validate() refuses "".
    return KeyValue{enum_name(names_of(v), v)};
  } else if constexpr (EnumList<T>) {
    std::vector<std::string_view> names;
    for (const auto item : v) names.push_back(enum_name(names_of(item), item));
    return KeyValue{std::move(names)};
  } else if constexpr (std::is_same_v<T, std::string>) {
    return KeyValue{std::string_view(v)};  // a view into the owner's string
  } else {
    return KeyValue{v};
  }
}

template <class E>
E enum_of(std::string_view name) {
  // The reader and validate() only store names from the key's list.
  return enum_value(names_of(E{}), name).value_or(E{});
}

template <class T>
void from_value(const KeyValue& v, T& out) {
  if constexpr (Optional<T>) {
    typename OptionalOf<T>::type inner{};
    from_value(v, inner);
    out = inner;
  } else if constexpr (Count<T>) {
    out = static_cast<T>(std::get<std::uint64_t>(v));
  } else if constexpr (NamedEnum<T>) {
    out = enum_of<T>(std::get<std::string_view>(v));
  } else if constexpr (EnumList<T>) {
    out.clear();
    for (const auto name : std::get<std::vector<std::string_view>>(v)) out.push_back(enum_of<typename T::value_type>(name));
  } else if constexpr (std::is_same_v<T, std::string>) {
    out = std::string(std::get<std::string_view>(v));
  } else {
    out = std::get<T>(v);
  }
}

// `spec` for the field `locate` finds: locate(owner) is a pointer to it, or
// nullptr when the owner has no such field (its section is absent). Type and
// names come from the field's type.
template <class Owner, class Locate>
KeySpec<Owner> field(KeySpec<Owner> spec, Locate locate) {
  using T = std::remove_cvref_t<decltype(*locate(std::declval<Owner&>()))>;
  spec.type = key_type<T>();
  spec.names = names_for<T>();
  spec.get = [locate](const Owner& o) -> std::optional<KeyValue> {
    const auto* p = locate(o);
    if (!p) return std::nullopt;
    return to_value(*p);
  };
  spec.set = [locate](Owner& o, const KeyValue& v) {
    if (auto* p = locate(o)) from_value(v, *p);
  };
  return spec;
}

// Locators. A section's fields exist only when the section does.
template <class M>
auto in_scene(M Scene::*member) {
  return [member](auto& s) { return &(s.*member); };
}
template <class M>
auto in_sph(M sph::SphParameters::*member) {
  return [member](auto& s) { return s.sph ? &((*s.sph).*member) : nullptr; };
}
template <class M>
auto in_nbody(M gravity::GravitySettings::*member) {
  return [member](auto& s) { return s.nbody ? &((*s.nbody).*member) : nullptr; };
}
template <class M>
auto in_random_box(M Scene::RandomBox::*member) {
  return [member](auto& s) { return s.random_box ? &((*s.random_box).*member) : nullptr; };
}
template <class Source, class M>
auto in_source(M Source::*member) {
  return [member](auto& src) {
    auto* s = std::get_if<Source>(&src);
    return s ? &(s->*member) : nullptr;
  };
}

// A field of an obstacle's `motion`: present when the obstacle moves with a
// kind that uses it (`kinds`: a bit per RigidMotion::Kind), so that a key of
// another kind is neither hashed nor checked, and a static obstacle has none.
template <class M>
auto in_motion(M boundary::RigidMotion::*member, unsigned kinds) {
  return [member, kinds](auto& src) {
    auto* o = std::get_if<ObstacleSource>(&src);
    using Pointer = decltype(&((*o->motion).*member));
    if (!o || !o->motion || !(kinds & (1u << static_cast<unsigned>(o->motion->kind)))) return Pointer(nullptr);
    return &((*o->motion).*member);
  };
}

constexpr Range kPositive{0, std::numeric_limits<double>::infinity(), true, false};
constexpr Range kNonNegative{0, std::numeric_limits<double>::infinity(), false, false};
constexpr Range kUnit{0, 1, false, false};
constexpr Range kFraction{0, 1, true, false};
constexpr Range kAtLeastOne{1, std::numeric_limits<double>::infinity(), false, false};
// Counts of particles a source may make: 1 to 2^31.
constexpr Range kParticleCount{1, static_cast<double>(detail::kMaxParticles), false, false};
// Sizes of tree nodes and groups: 1 to 2^20.
constexpr Range kTreeSize{1, 1 << 20, false, false};
// The FMM's expansion orders (fmm.hpp).
constexpr Range kFmmOrder{2, 5, false, false};
// A length beyond 1e9 m is a typo; it would also overflow h³.
constexpr Range kSupport{0, 1e9, true, false};
constexpr Range kNeighbourCount{0, 10000, true, false};

using SceneKey = KeySpec<Scene>;
using SourceKey = KeySpec<ParticleSource>;

std::vector<SceneKey> declare_scene_keys() {
  std::vector<SceneKey> k;
  const auto add = [&](SceneKey spec) { k.push_back(std::move(spec)); };

  // The root.
  add(field(SceneKey{.key = "format", .section = "", .range = kAtLeastOne,
                     .doc = "the scene format version: absent means the current one; a newer one is refused",
                     .custom_read = true, .hashed = false},
            in_scene(&Scene::format_version)));

  // [simulation]
  add(field(SceneKey{.key = "simulation.precision", .section = "simulation", .noun = "precision",
                     .doc = "the floating-point type of the particle fields and the solver",
                     .default_doc = "`\"float\"`, `\"double\"` with `[nbody]`",
                     .context_default = [](const Scene& s) { return to_value(s.nbody ? Precision::Double : Precision::Float); }},
            in_scene(&Scene::precision)));
  add(field(SceneKey{.key = "simulation.units", .section = "simulation", .noun = "unit system",
                     .doc = "`\"si\"`: m, s, kg, G = 6.67430e-11 m³ kg⁻¹ s⁻²; `\"nbody\"`: G = 1 (or `nbody.G`)",
                     .default_doc = "`\"nbody\"` with `[nbody]` and no `[sph]`, else `\"si\"`",
                     .context_default = [](const Scene& s) {
                       return to_value(s.nbody && !s.sph ? Units::NBody : Units::SI);
                     }},
            in_scene(&Scene::units)));
  SceneKey dt{.key = "simulation.dt", .section = "simulation", .type = KeyType::Number, .unit = "s",
              .range = kPositive,
              .doc = "the time step; `\"adaptive\"`: every step chosen from the conditions below ([stability.md](stability.md))",
              .required = true, .type_doc = "number or `\"adaptive\"`", .custom_read = true};
  dt.get = [](const Scene& s) -> std::optional<KeyValue> {
    if (s.adaptive_dt) return KeyValue{std::string_view("adaptive")};
    return KeyValue{s.dt};
  };
  add(std::move(dt));
  add(field(SceneKey{.key = "simulation.end_time", .section = "simulation", .unit = "s", .range = kPositive,
                     .doc = "the simulated time to run; exactly one of `end_time` and `steps` is required",
                     .default_doc = "–", .custom_read = true},
            in_scene(&Scene::end_time)));
  add(field(SceneKey{.key = "simulation.steps", .section = "simulation", .range = kAtLeastOne,
                     .doc = "the number of steps; exactly one of `end_time` and `steps` is required",
                     .default_doc = "–", .custom_read = true},
            in_scene(&Scene::steps)));
  add(field(SceneKey{.key = "simulation.block_size", .section = "simulation", .unit = "particles", .range = kAtLeastOne,
                     .doc = "particles per parallel work block; results are identical for any thread count at a given block size"},
            in_scene(&Scene::block_size)));
  add(field(SceneKey{.key = "simulation.rebalance_threshold", .section = "simulation", .unit = "–", .range = kAtLeastOne,
                     .doc = "on several MPI ranks: the ranks' key ranges are cut anew when the largest rank's work "
                            "(1 per particle plus its neighbour candidates or interaction-list entries in the last "
                            "step) over the mean passes this; 1 = at every sort. Changes no result, only the balance",
                     // The trajectory does not depend on it: not in the checkpoints' scene hash.
                     .hashed = false},
            in_scene(&Scene::rebalance_threshold)));
  SceneKey dt_max{.key = "simulation.dt_max", .section = "simulation", .type = KeyType::Number, .unit = "s",
                  .range = kPositive,
                  .doc = "only with `dt = \"adaptive\"`: the largest step; required when the default does not apply "
                         "or the scene has neither `[sph]` nor `[nbody]`",
                  .default_doc = "`output.interval` (else `end_time`)", .custom_read = true};
  dt_max.get = [](const Scene& s) -> std::optional<KeyValue> {
    if (!s.adaptive_dt) return std::nullopt;
    return KeyValue{s.dt};
  };
  add(std::move(dt_max));
  SceneKey dt_min{.key = "simulation.dt_min", .section = "simulation", .type = KeyType::Number, .unit = "s",
                  .range = kNonNegative,
                  .doc = "only with `dt = \"adaptive\"`: a smaller step is a blow-up (the step collapsed); < `dt_max`",
                  .default_doc = "1e-6 × the first step", .custom_read = true};
  dt_min.get = [](const Scene& s) -> std::optional<KeyValue> {
    if (!s.adaptive_dt) return std::nullopt;
    return KeyValue{s.dt_min};
  };
  add(std::move(dt_min));
  add(field(SceneKey{.key = "simulation.cfl", .section = "simulation", .range = kFraction,
                     .doc = "C_cfl, SPH Δt ≤ C_cfl·h / (c + \\|v\\|max)"},
            in_scene(&Scene::cfl)));
  add(field(SceneKey{.key = "simulation.force_factor", .section = "simulation", .range = kFraction,
                     .doc = "C_force, SPH Δt ≤ C_force·sqrt(h / \\|a\\|max)"},
            in_scene(&Scene::force_factor)));
  add(field(SceneKey{.key = "simulation.viscous_factor", .section = "simulation", .range = kFraction,
                     .doc = "C_visc, SPH Δt ≤ C_visc·h²·ρ / μ"},
            in_scene(&Scene::viscous_factor)));
  add(field(SceneKey{.key = "simulation.eta", .section = "simulation", .range = Range{0, 10, true, false},
                     .doc = "η, gravity Δt ≤ η·sqrt(ε / \\|a\\|max) (ε = 0: the mean particle spacing in place of ε)"},
            in_scene(&Scene::eta)));
  add(field(SceneKey{.key = "simulation.time_steps", .section = "simulation", .noun = "time-step scheme",
                     .doc = "`\"global\"`: one step for every particle; `\"block\"` (needs `[nbody]` with a softening "
                            "> 0, a fixed `dt`, no walls): each particle in its own bin dt/2^k by η·sqrt(ε/\\|a_i\\|), "
                            "forces only for the particles whose steps end ([gravity.md](gravity.md))",
                     .unhashed_value = "global"},
            in_scene(&Scene::time_steps)));
  add(field(SceneKey{.key = "simulation.max_bin", .section = "simulation", .range = Range{0, 40},
                     .doc = "only with `time_steps = \"block\"`: the finest bin, dt/2^max_bin; a particle that needs a "
                            "finer one is a blow-up"},
            [](auto& s) { return s.time_steps == TimeSteps::Block ? &s.max_bin : nullptr; }));
  add(field(SceneKey{.key = "simulation.max_energy_error", .section = "simulation", .range = kNonNegative,
                     .doc = "a run whose forces and walls all conserve energy stops (a blow-up) when its relative "
                            "energy error \\|E − E0\\|/\\|E0\\| at an output time exceeds this (0 = never)",
                     // A guard, not physics: the trajectory and so the checkpoints' scene hash do not depend on it.
                     .hashed = false},
            in_scene(&Scene::max_energy_error)));

  // [box]: the walls. A random box derives min and max itself.
  const auto box_corner = [](Vec3d Box<double>::*corner) {
    return [corner](auto& s) { return s.walls ? &(s.box.*corner) : nullptr; };
  };
  add(field(SceneKey{.key = "box.min", .section = "box", .unit = "m", .doc = "the low corner", .required = true},
            box_corner(&Box<double>::lo)));
  add(field(SceneKey{.key = "box.max", .section = "box", .unit = "m",
                     .doc = "the high corner, greater than `min` on every axis", .required = true},
            box_corner(&Box<double>::hi)));
  add(field(SceneKey{.key = "box.restitution", .section = "box", .range = kUnit,
                     .doc = "the fraction of its normal velocity a particle keeps when it hits a wall"},
            [](auto& s) { return s.walls ? &s.restitution : nullptr; }));
  add(field(SceneKey{.key = "box.walls", .section = "box", .noun = "wall kind",
                     .doc = "`\"clamp\"` (the thesis's two passes: velocities reflected, positions projected) or "
                            "`\"particles\"` (boundary particles, Akinci et al. 2012, one layer at the first "
                            "`fluid_block`'s spacing just outside each face, where a fluid block filling the box starts "
                            "at the rest density; needs `[sph]` with the grid search; the clamp stays one spacing "
                            "further out as a safety net); docs/sph.md",
                     .unhashed_value = "clamp"},
            [](auto& s) { return s.walls ? &s.wall_kind : nullptr; }));

  // [forces]
  add(field(SceneKey{.key = "forces.gravity", .section = "forces", .unit = "m/s²",
                     .doc = "a uniform acceleration (use `[0, 0, 0]` for none)",
                     .default_doc = "`[0, 0, -9.81]`, `[0, 0, 0]` with `[nbody]`",
                     .context_default = [](const Scene& s) -> std::optional<KeyValue> {
                       // A self-gravitating system floats in open space unless told otherwise.
                       if (s.nbody) return KeyValue{Vec3d{}};
                       return std::nullopt;
                     }},
            in_scene(&Scene::gravity)));
  add(field(SceneKey{.key = "forces.damping", .section = "forces", .unit = "1/s", .range = kNonNegative,
                     .doc = "γ of a drag a = −γ·v, for settling runs (0: none)"},
            in_scene(&Scene::damping)));

  // [sph]
  add(field(SceneKey{.key = "sph.smoothing_length", .section = "sph", .unit = "m", .range = kSupport,
                     .doc = "h, the kernel support and the hash cell length; exactly one of it and `neighbours`",
                     .default_doc = "–", .custom_read = true},
            in_sph(&sph::SphParameters::smoothing_length)));
  add(SceneKey{.key = "sph.neighbours", .section = "sph", .type = KeyType::Number, .range = kNeighbourCount,
               .doc = "h from a target neighbour count k and the spacing s of the first `fluid_block`, "
                      "h = (3(k+1)s³/(4π))^(1/3)",
               .default_doc = "–", .custom_read = true,
               // Only a way to give h, which is hashed.
               .get = [](const Scene&) -> std::optional<KeyValue> { return std::nullopt; }});
  add(field(SceneKey{.key = "sph.method", .section = "sph", .noun = "SPH method",
                     .doc = "`\"wcsph\"` (the thesis's weakly compressible fluid, p = c²(ρ − ρ0)) or `\"dfsph\"` "
                            "(divergence-free SPH, Bender & Koschier 2015/2017: a constant-density and a "
                            "divergence-free solve per step, iterated to `sph.dfsph.*` tolerances; needs the grid "
                            "search); docs/sph.md",
                     .unhashed_value = "wcsph"},
            in_sph(&sph::SphParameters::method)));
  add(field(SceneKey{.key = "sph.kernel", .section = "sph", .noun = "kernel",
                     .doc = "DFSPH's kernels: `\"cubic_spline\"` (Monaghan 1992, W and its own gradient) or "
                            "`\"thesis\"` (W_poly6 density, ∇W_spiky gradients); the thesis's solver takes "
                            "`\"thesis\"` only",
                     .default_doc = "`\"cubic_spline\"` with `method = \"dfsph\"`, else `\"thesis\"`",
                     .unhashed_value = "thesis",
                     .context_default = [](const Scene& s) {
                       const bool dfsph = s.sph && s.sph->method == sph::SphMethod::Dfsph;
                       return to_value(dfsph ? sph::SphKernel::CubicSpline : sph::SphKernel::Thesis);
                     }},
            in_sph(&sph::SphParameters::kernel)));
  const auto in_dfsph = [](auto member) {
    return [member](auto& s) { return s.sph && s.sph->method == sph::SphMethod::Dfsph ? &(s.sph->dfsph.*member) : nullptr; };
  };
  add(field(SceneKey{.key = "sph.dfsph.density_tolerance", .section = "sph", .range = Range{0, 1, true, false},
                     .doc = "η: the constant-density solve iterates until the average compression "
                            "max(ρ* − ρ0, 0)/ρ0 is at most this (5e-4 = 0.05 %)",
                     .default_doc = "`5e-4` (with `method = \"dfsph\"`)"},
            in_dfsph(&sph::DfsphOptions::density_tolerance)));
  add(field(SceneKey{.key = "sph.dfsph.divergence_tolerance", .section = "sph", .range = Range{0, 1, true, false},
                     .doc = "η_v: the divergence-free solve iterates until the average max(Dρ/Dt, 0)·Δt/ρ0 is at "
                            "most this",
                     .default_doc = "`1e-3` (with `method = \"dfsph\"`)"},
            in_dfsph(&sph::DfsphOptions::divergence_tolerance)));
  add(field(SceneKey{.key = "sph.dfsph.max_iterations", .section = "sph", .range = Range{1, 1e6},
                     .doc = "the cap of either solve; a solve that reaches it above its tolerance stops the run "
                            "(blow-up \"solver did not converge\")",
                     .default_doc = "`100` (with `method = \"dfsph\"`)"},
            in_dfsph(&sph::DfsphOptions::max_iterations)));
  add(field(SceneKey{.key = "sph.dfsph.cfl", .section = "sph", .range = kFraction,
                     .doc = "C of DFSPH's CFL condition Δt ≤ C·h/\\|v\\|max (no sound speed: the fluid is "
                            "incompressible; 0.2·h ≈ 0.4 spacings at h ≈ 2 spacings)",
                     .default_doc = "`0.2` (with `method = \"dfsph\"`)"},
            in_dfsph(&sph::DfsphOptions::cfl)));
  add(field(SceneKey{.key = "sph.rest_density", .section = "sph", .unit = "kg/m³", .range = kPositive, .doc = "ρ0"},
            in_sph(&sph::SphParameters::rest_density)));
  add(field(SceneKey{.key = "sph.sound_speed", .section = "sph", .unit = "m/s", .range = kPositive,
                     .doc = "c in p = c²(ρ − ρ0)"},
            in_sph(&sph::SphParameters::sound_speed)));
  add(field(SceneKey{.key = "sph.viscosity", .section = "sph", .unit = "Pa·s", .range = kNonNegative, .doc = "μ"},
            in_sph(&sph::SphParameters::viscosity)));
  // DFSPH's non-pressure terms: keys added after checkpoints existed, left out of the hash when off.
  add(field(SceneKey{.key = "sph.xsph", .section = "sph", .range = kUnit,
                     .doc = "ε of the XSPH velocity filter v_i += ε Σ_j 2m_j/(ρ_i + ρ_j)·(v_j − v_i)·W_ij, once per "
                            "step after the velocity update (0: off; needs `method = \"dfsph\"`); docs/sph.md",
                     .unhashed_value = "0"},
            in_sph(&sph::SphParameters::xsph)));
  add(field(SceneKey{.key = "sph.surface_tension", .section = "sph", .range = kNonNegative,
                     .doc = "γ of Akinci et al. 2013's surface tension (cohesion and curvature, in the paper's "
                            "units; 0: off; needs `method = \"dfsph\"`); docs/sph.md",
                     .unhashed_value = "0"},
            in_sph(&sph::SphParameters::surface_tension)));
  add(field(SceneKey{.key = "sph.adhesion", .section = "sph", .range = kNonNegative,
                     .doc = "β of Akinci et al. 2013's adhesion of the fluid to boundary particles (0: off; needs "
                            "`method = \"dfsph\"` and boundary particles); docs/sph.md",
                     .unhashed_value = "0"},
            in_sph(&sph::SphParameters::adhesion)));
  add(field(SceneKey{.key = "sph.gradient_correction", .section = "sph",
                     .doc = "corrects the pressure force by M_i⁻¹ (Bonet & Lok's kernel-gradient renormalisation: exact "
                            "for a linear pressure field; not momentum-conserving; off where det M_i < 0.5, as at a "
                            "free surface); docs/sph.md",
                     .unhashed_value = "false"},
            in_sph(&sph::SphParameters::gradient_correction)));
  add(field(SceneKey{.key = "sph.pressure", .section = "sph", .noun = "pressure form",
                     .doc = "`\"thesis\"` (eq. 2.8, applies ½∇p) or `\"consistent\"` (see docs/sph.md)"},
            in_sph(&sph::SphParameters::pressure_form)));
  add(field(SceneKey{.key = "sph.negative_pressure", .section = "sph", .noun = "negative pressure rule",
                     .doc = "`\"keep\"` (eq. 2.9) or `\"zero\"` (no tension)"},
            in_sph(&sph::SphParameters::negative_pressure)));
  add(field(SceneKey{.key = "sph.neighbour_search", .section = "sph", .noun = "neighbour search",
                     .doc = "`\"grid\"` (sorted cell grid, particles reordered in memory every step) or `\"hash\"` "
                            "(the thesis's spatial hash); docs/sph.md"},
            in_sph(&sph::SphParameters::neighbour_search)));
  add(field(SceneKey{.key = "sph.grid.simd", .section = "sph",
                     .doc = "grid: explicit SIMD passes (and, in float, DFSPH's solve passes over its kept pairs); "
                            "`false` runs their scalar twins (for comparison)"},
            in_sph(&sph::SphParameters::simd)));
  add(field(SceneKey{.key = "sph.grid.cell_order", .section = "sph", .noun = "cell order",
                     .doc = "grid: `\"rows\"` (row-major cells, 9 ranges per cell) or `\"morton\"` (Z-order, up to 27); "
                            "docs/performance/sph-grid.md"},
            in_sph(&sph::SphParameters::cell_order)));
  add(field(SceneKey{.key = "sph.grid.table", .section = "sph", .noun = "cell table",
                     .doc = "grid: how cells are found: `\"dense\"` (a table over the box's cells), `\"hashed\"` (a hash "
                            "table of the occupied cells, for particles spread over a huge region) or `\"auto\"` "
                            "(dense while the box has at most 4·N + 4096 cell keys)"},
            in_sph(&sph::SphParameters::cell_table)));
  add(field(SceneKey{.key = "sph.grid.skin", .section = "sph", .unit = "m", .range = Range{0, 1e9, false, false},
                     .doc = "grid: Verlet skin; cells of h + skin, the sort skipped until a particle moved more than "
                            "skin/2 (0 = sort every evaluation)"},
            in_sph(&sph::SphParameters::grid_skin)));
  add(field(SceneKey{.key = "sph.hash.buckets", .section = "sph", .range = Range{0, 0xffffffffu, false, false},
                     .doc = "0 = 1.6·N made odd (the thesis's table size), else the bucket count M"},
            in_sph(&sph::SphParameters::buckets)));
  add(field(SceneKey{.key = "sph.hash.duplicate_check", .section = "sph",
                     .doc = "the thesis's cell-relation check against duplicate interactions"},
            in_sph(&sph::SphParameters::duplicate_check)));
  add(field(SceneKey{.key = "sph.hash.check_placement", .section = "sph", .noun = "check placement",
                     .doc = "where the duplicate check runs: `\"before_distance\"` (ours: a colliding entry costs no "
                            "distance test) or `\"after_distance\"` (the thesis's place, section 4.2.3: the cells of "
                            "the pairs within h); the same pairs in the same order either way",
                     .hashed = false},
            in_sph(&sph::SphParameters::check_placement)));
  add(field(SceneKey{.key = "sph.hash.table_build", .section = "sph", .noun = "table build",
                     .doc = "hash: the table's counting sort on every thread (`\"parallel\"`) or on one "
                            "(`\"serial\"`, as the thesis's PPE built it: its serial portion); the same table",
                     .hashed = false},
            in_sph(&sph::SphParameters::table_build)));
  add(field(SceneKey{.key = "sph.hash.neighbour_hashes", .section = "sph", .noun = "neighbour hashing",
                     .doc = "hash: the buckets of the 26 cells around a particle's, hashed by the search as it scans "
                            "them (`\"on_the_fly\"`) or precomputed per particle while the table is built "
                            "(`\"precomputed\"`, the thesis's section 4.2.3); the same pairs in the same order",
                     .hashed = false},
            in_sph(&sph::SphParameters::neighbour_hashes)));

  // [random_box] with the root key `particles`.
  add(field(SceneKey{.key = "particles", .section = "random_box", .unit = "particles", .range = kParticleCount,
                     .doc = "N, a root key in place of `[[particles]]`", .required = true, .custom_read = true},
            in_random_box(&Scene::RandomBox::particles)));
  add(field(SceneKey{.key = "random_box.neighbours", .section = "random_box", .range = kNeighbourCount, .doc = "k"},
            in_random_box(&Scene::RandomBox::neighbours)));
  add(field(SceneKey{.key = "random_box.seed", .section = "random_box", .range = kNonNegative,
                     .doc = "seeds the positions"},
            in_random_box(&Scene::RandomBox::seed)));

  // [nbody]
  using gravity::GravitySettings;
  const auto linear_tree = [](const Scene& s) { return s.nbody && s.nbody->tree == gravity::Tree::Linear; };
  add(field(SceneKey{.key = "nbody.method", .section = "nbody", .noun = "method",
                     .doc = "`\"barnes_hut\"`, `\"direct\"` (the exact O(N²) sum) or `\"fmm\"` (the fast multipole "
                            "method: mutual cell–cell expansions of order `fmm_order` on the linear octree; "
                            "docs/gravity.md)"},
            in_nbody(&GravitySettings::method)));
  add(field(SceneKey{.key = "nbody.scheme", .section = "nbody", .noun = "scheme",
                     .doc = "`\"subdomain\"`, `\"subtree\"` (the paper's 4.1, 4.2) or `\"global\"`"},
            in_nbody(&GravitySettings::scheme)));
  add(field(SceneKey{.key = "nbody.opening", .section = "nbody", .range = kUnit,
                     .doc = "λ (paper rule) or θ (Barnes' rule); `fmm`: θ of the acceptance r_A + r_B < θ·|z_A − z_B| "
                            "(cell radii about the centres of mass); 0 gives the direct sum"},
            in_nbody(&GravitySettings::opening)));
  add(field(SceneKey{.key = "nbody.softening", .section = "nbody", .unit = "length", .range = kNonNegative,
                     .doc = "Plummer softening ε"},
            in_nbody(&GravitySettings::softening)));
  add(field(SceneKey{.key = "nbody.subdomain_size", .section = "nbody", .unit = "particles", .range = kAtLeastOne,
                     .doc = "particles per local tree (subdomain)"},
            in_nbody(&GravitySettings::subdomain_size)));
  add(field(SceneKey{.key = "nbody.subtree_nodes", .section = "nbody", .unit = "nodes", .range = kAtLeastOne,
                     .doc = "nodes per unit (subtree)"},
            in_nbody(&GravitySettings::subtree_nodes)));
  // Keys added after checkpoints existed: the old behaviour's value stays out of the scene hash.
  add(field(SceneKey{.key = "nbody.subdomain_split", .section = "nbody", .noun = "subdomain split",
                     .doc = "subdomain: `\"adaptive\"` (Morton cells split from the root while over `subdomain_size`; "
                            "ours) or `\"paper\"` (the paper's fixed 512 cells packed into sub-domains of ≤ "
                            "`subdomain_size`); docs/gravity.md",
                     .unhashed_value = "adaptive"},
            in_nbody(&GravitySettings::subdomain_split)));
  add(field(SceneKey{.key = "nbody.subtree_split", .section = "nbody", .noun = "subtree split",
                     .doc = "subtree: `\"units\"` (units of ≤ `subtree_nodes` nodes; ours) or `\"parts\"` (the paper's: "
                            "the node total divided by `subtree_parts`)",
                     .unhashed_value = "units"},
            in_nbody(&GravitySettings::subtree_split)));
  add(field(SceneKey{.key = "nbody.subtree_parts", .section = "nbody", .unit = "units", .range = kAtLeastOne,
                     .doc = "subtree with `subtree_split = \"parts\"`: the paper's number of SPEs (a scene value, not the "
                            "thread count, so that results do not depend on the threads)",
                     .unhashed_value = "8"},
            in_nbody(&GravitySettings::subtree_parts)));
  add(field(SceneKey{.key = "nbody.upper_nodes", .section = "nbody", .noun = "upper-node rule",
                     .doc = "subtree: the nodes above the units are `\"opened\"` always (ours) or used as `\"clusters\"` "
                            "by every unit, counted by one (the paper's replicated upper levels: the global walk's "
                            "field)",
                     .unhashed_value = "opened"},
            in_nbody(&GravitySettings::upper_nodes)));
  add(field(SceneKey{.key = "nbody.tree", .section = "nbody", .noun = "tree",
                     .doc = "`\"linear\"` (the octree from sorted Morton keys) or `\"paper\"` (the paper's "
                            "insertion-built tree); `\"linear\"` needs `scheme = \"global\"`",
                     .default_doc = "`\"linear\"` with `scheme = \"global\"`, else `\"paper\"`",
                     .context_default = [](const Scene& s) {
                       const bool global = s.nbody && s.nbody->scheme == gravity::Scheme::Global;
                       return to_value(global ? gravity::Tree::Linear : gravity::Tree::Paper);
                     }},
            in_nbody(&GravitySettings::tree)));
  add(field(SceneKey{.key = "nbody.multipole", .section = "nbody", .noun = "multipole",
                     .doc = "`\"monopole\"` or `\"quadrupole\"`; the paper tree is monopole only",
                     .default_doc = "`\"quadrupole\"` (linear tree), `\"monopole\"` (paper tree)",
                     .context_default = [linear_tree](const Scene& s) {
                       return to_value(linear_tree(s) ? gravity::Multipole::Quadrupole : gravity::Multipole::Monopole);
                     }},
            in_nbody(&GravitySettings::multipole)));
  add(field(SceneKey{.key = "nbody.opening_criterion", .section = "nbody", .noun = "opening criterion",
                     .doc = "`\"barnes\"` (open if d < l/θ + δ, θ = `opening`) or `\"paper\"` (open if l/d ≥ λ); the "
                            "paper tree takes `\"paper\"` only",
                     .default_doc = "`\"barnes\"` (linear tree), `\"paper\"` (paper tree)",
                     .context_default = [linear_tree](const Scene& s) {
                       return to_value(linear_tree(s) ? gravity::Criterion::Barnes : gravity::Criterion::Paper);
                     }},
            in_nbody(&GravitySettings::criterion)));
  add(field(SceneKey{.key = "nbody.bucket_size", .section = "nbody", .unit = "particles", .range = kTreeSize,
                     .doc = "a linear-tree node with more particles is split",
                     // The FMM's P2P takes whole leaves, its M2L whole cells: larger leaves cost it less (0.67–0.75×
                     // the time of 32 at 2^16–2^20, docs/performance/fmm.md); Barnes–Hut is fastest near 16.
                     .default_doc = "`16`; `64` with `method = \"fmm\"`",
                     .context_default = [](const Scene& s) {
                       return to_value(std::size_t(s.nbody && s.nbody->method == gravity::Method::Fmm ? 64 : 16));
                     }},
            in_nbody(&GravitySettings::bucket_size)));
  add(field(SceneKey{.key = "nbody.walk", .section = "nbody", .noun = "walk",
                     .doc = "`\"group\"` (one walk per group of ≤ `group_size` particles, its interaction list evaluated "
                            "by the SIMD kernels) or `\"particle\"` (one walk per particle, the reference); the paper "
                            "tree takes `\"particle\"` only",
                     .default_doc = "`\"group\"` (linear tree), `\"particle\"` (paper tree)",
                     .context_default = [linear_tree](const Scene& s) {
                       return to_value(linear_tree(s) ? gravity::Walk::Group : gravity::Walk::Particle);
                     }},
            in_nbody(&GravitySettings::walk)));
  add(field(SceneKey{.key = "nbody.group_size", .section = "nbody", .unit = "particles", .range = kTreeSize,
                     .doc = "the group walk's groups hold at most this many particles (unless one leaf holds more); "
                            "256–512 was fastest at the accuracy target (docs/performance/gravity-tree.md)"},
            in_nbody(&GravitySettings::group_size)));
  add(field(SceneKey{.key = "nbody.simd", .section = "nbody",
                     .doc = "linear tree: explicit SIMD interaction kernels; `false` runs their scalar twin (for "
                            "comparison)",
                     // Not hashed, so that checkpoints of scenes from before the key keep their hash: it changes
                     // rounding only, and a resume reads the value from the scene saved with the run.
                     .hashed = false},
            in_nbody(&GravitySettings::simd)));
  add(field(SceneKey{.key = "nbody.fmm_order", .section = "nbody", .range = kFmmOrder,
                     .doc = "`fmm`: the expansion order p (multipoles to order p; the force error falls as θ^(p+1))",
                     // Added after checkpoints existed: the default stays out of the scene hash.
                     .unhashed_value = "3"},
            in_nbody(&GravitySettings::fmm_order)));
  add(field(SceneKey{.key = "nbody.G", .section = "nbody", .unit = "length³/(mass·time²)", .range = kPositive,
                     .doc = "the gravitational constant, in the scene's units",
                     .default_doc = "`1` with `units = \"nbody\"`, `6.6743e-11` with `\"si\"`",
                     .context_default = [](const Scene& s) {
                       return to_value(s.units == Units::NBody ? 1.0 : kGravitationalConstantSI);
                     }},
            [](auto& s) { return s.nbody ? &s.gravitational_constant : nullptr; }));

  // [output]
  add(field(SceneKey{.key = "output.interval", .section = "output", .unit = "s (simulated)", .range = kNonNegative,
                     .doc = "`0` writes only the first and the last frame"},
            in_scene(&Scene::output_interval)));
  add(field(SceneKey{.key = "output.format", .section = "output", .noun = "format",
                     .doc = "each `\"vtp\"` (VTK XML PolyData, for ParaView), `\"hdf5\"` (Gadget-format HDF5 "
                            "snapshots with an XDMF series for ParaView: docs/scenes.md, Output) or `\"csv\"`; an "
                            "array names at least one and none twice",
                     .type_doc = "string or array of strings"},
            in_scene(&Scene::formats)));
  // The surface keys change files beside the frames, never the run: not hashed.
  add(field(SceneKey{.key = "output.surface", .section = "output", .noun = "surface format",
                     .doc = "`\"ply\"` writes the fluid's surface with each frame, `surface_NNNNNN.ply` (binary "
                            "triangle mesh with normals, for Blender and ParaView; series in `surface.ply.series`), "
                            "`\"obj\"` as `surface_NNNNNN.obj` (Wavefront OBJ text, no series: ParaView's OBJ reader "
                            "takes one file); needs `[sph]` and a `\"vtp\"` or `\"hdf5\"` frame format "
                            "(docs/surface.md)",
                     .hashed = false},
            in_scene(&Scene::surface)));
  add(field(SceneKey{.key = "output.surface_radius", .section = "output", .unit = "particle spacings",
                     .range = Range{0.5, 8, false, false},
                     .doc = "the surface's smoothing-kernel radius, in particle spacings (m/ρ0)^(1/3)",
                     .hashed = false},
            in_scene(&Scene::surface_radius)));
  add(field(SceneKey{.key = "output.surface_cell", .section = "output", .unit = "particle spacings",
                     .range = Range{0.05, 4, false, false},
                     .doc = "the surface's grid cell, in particle spacings (finer: smoother, slower)",
                     .hashed = false},
            in_scene(&Scene::surface_cell)));
  add(field(SceneKey{.key = "output.surface_iso", .section = "output", .range = Range{0, 1, true, true},
                     .doc = "the level of the colour field the surface is drawn at (`0.5`: where a flat fluid ends)",
                     .hashed = false},
            in_scene(&Scene::surface_iso)));
  // probes.csv: keys added after checkpoints existed, left out of the hash at their defaults.
  add(field(SceneKey{.key = "output.probes_interval", .section = "output", .unit = "s (simulated)", .range = kNonNegative,
                     .doc = "how often `probes.csv` gets a row (the `[[probes]]`, and the obstacles' forces with "
                            "`obstacle_forces`); `0`: at `output.interval` (docs/sph.md, Probes)",
                     .unhashed_value = "0"},
            in_scene(&Scene::probes_interval)));
  add(field(SceneKey{.key = "output.obstacle_forces", .section = "output",
                     .doc = "`probes.csv` also records the force and torque the fluid exerts on each obstacle (and on "
                            "walls of particles, as `walls`): columns `<name>_force_x` ... `<name>_torque_z`, in N and "
                            "N·m about the obstacle's centre (needs boundary particles)",
                     .unhashed_value = "false"},
            in_scene(&Scene::obstacle_forces)));
  return k;
}

// ---- [[particles]] -----------------------------------------------------------

SourceKey region_corner(std::string_view key, Vec3d Box<double>::*corner, std::string_view doc) {
  SourceKey spec{.key = key, .type = KeyType::Vector, .unit = "m", .doc = doc, .required = true};
  const auto locate = [corner](auto& src) {
    using Pointer = decltype(&(std::get_if<LatticeSource>(&src)->region.*corner));  // const for a const source
    if (auto* l = std::get_if<LatticeSource>(&src)) return Pointer{&(l->region.*corner)};
    if (auto* r = std::get_if<RandomSource>(&src)) return Pointer{&(r->region.*corner)};
    if (auto* o = std::get_if<ObstacleSource>(&src)) return Pointer{&(o->region.*corner)};
    return Pointer{nullptr};
  };
  return field(std::move(spec), locate);
}

template <class Source>
SourceKey seed_key(std::string_view doc) {
  return field(SourceKey{.key = "seed", .range = kNonNegative, .doc = doc}, in_source(&Source::seed));
}

template <class Source>
SourceKey velocity_key(std::string_view doc) {
  return field(SourceKey{.key = "velocity", .unit = "m/s", .doc = doc}, in_source(&Source::velocity));
}

std::vector<SourceKey> lattice_keys(bool fluid) {
  std::vector<SourceKey> k;
  k.push_back(region_corner("min", &Box<double>::lo, "the region's low corner, inside the box"));
  k.push_back(region_corner("max", &Box<double>::hi,
                            "the region's high corner, inside the box, greater than `min` on every axis"));
  k.push_back(field(SourceKey{.key = "spacing", .unit = "m", .range = kPositive, .doc = "the lattice constant",
                              .required = true},
                    in_source(&LatticeSource::spacing)));
  k.push_back(field(SourceKey{.key = "jitter", .unit = "fraction of `spacing`", .range = Range{0, 0.5, false, true},
                              .doc = "each coordinate moves by up to jitter·spacing"},
                    in_source(&LatticeSource::jitter)));
  k.push_back(seed_key<LatticeSource>("seeds the jitter"));
  if (!fluid)
    k.push_back(field(SourceKey{.key = "mass", .unit = "kg", .range = kPositive, .doc = "the mass of every particle",
                                .required = true},
                      in_source(&LatticeSource::mass)));
  k.push_back(velocity_key<LatticeSource>("the initial velocity of every particle"));
  return k;
}

std::vector<SourceKey> random_keys() {
  std::vector<SourceKey> k;
  k.push_back(region_corner("min", &Box<double>::lo, "the region's low corner, inside the box"));
  k.push_back(region_corner("max", &Box<double>::hi,
                            "the region's high corner, inside the box, greater than `min` on every axis"));
  k.push_back(field(SourceKey{.key = "count", .range = kParticleCount, .doc = "the number of particles", .required = true},
                    in_source(&RandomSource::count)));
  k.push_back(seed_key<RandomSource>("seeds the positions"));
  k.push_back(field(SourceKey{.key = "mass", .unit = "kg", .range = kPositive, .doc = "the mass of every particle",
                              .required = true},
                    in_source(&RandomSource::mass)));
  k.push_back(velocity_key<RandomSource>("the initial velocity of every particle"));
  return k;
}

std::vector<SourceKey> list_keys() {
  std::vector<SourceKey> k;
  k.push_back(field(SourceKey{.key = "positions", .unit = "m", .doc = "at least one; each inside the box",
                              .required = true, .custom_read = true},
                    in_source(&ListSource::positions)));
  k.push_back(field(SourceKey{.key = "velocities", .unit = "m/s", .doc = "one per position",
                              .default_doc = "all at rest", .custom_read = true},
                    in_source(&ListSource::velocities)));
  k.push_back(SourceKey{.key = "mass", .type = KeyType::Number, .unit = "kg", .range = kPositive,
                        .doc = "the mass of every particle; exactly one of `mass` and `masses` is required",
                        .default_doc = "–", .custom_read = true,
                        // Stored as `masses`, one per position.
                        .get = [](const ParticleSource&) -> std::optional<KeyValue> { return std::nullopt; }});
  k.push_back(field(SourceKey{.key = "masses", .unit = "kg", .range = kPositive, .doc = "one per position",
                              .default_doc = "–", .custom_read = true},
                    in_source(&ListSource::masses)));
  return k;
}

std::vector<SourceKey> stellar_keys(StellarSource::Model model) {
  using Model = StellarSource::Model;
  std::vector<SourceKey> k;
  k.push_back(field(SourceKey{.key = "count", .range = kParticleCount, .doc = "the number of particles",
                              .required = true},
                    in_source(&StellarSource::count)));
  k.push_back(seed_key<StellarSource>("seeds the model"));
  // A field of one model's options (StellarSource::plummer, ::collision, ::hernquist, ::nfw, ::king, ::disk).
  const auto in_options = [](auto options, auto member) {
    return [options, member](auto& src) {
      auto* m = std::get_if<StellarSource>(&src);
      return m ? &((m->*options).*member) : nullptr;
    };
  };
  const auto collision = [&](auto member) { return in_options(&StellarSource::collision, member); };
  switch (model) {
    case Model::Plummer:
      k.push_back(field(SourceKey{.key = "mass_cut", .range = kFraction,
                                  .doc = "the fraction of the infinite model's mass kept (its outskirts cut)"},
                        in_options(&StellarSource::plummer, &gravity::PlummerOptions::mass_cut)));
      break;
    case Model::UniformSphere:
    case Model::UniformCube:
      k.push_back(field(SourceKey{.key = model == Model::UniformSphere ? "radius" : "side", .unit = "length",
                                  .range = kPositive, .doc = "the size"},
                        in_source(&StellarSource::size)));
      k.push_back(field(SourceKey{.key = "mass", .unit = "mass", .range = kPositive, .doc = "the total mass"},
                        in_source(&StellarSource::mass)));
      break;
    case Model::ColdCollapse: break;
    case Model::PlummerCollision:
      k.push_back(field(SourceKey{.key = "mass_fraction", .range = Range{0, 1, true, true},
                                  .doc = "the first sphere's share of the particles and the mass"},
                        collision(&gravity::CollisionOptions::mass_fraction)));
      k.push_back(field(SourceKey{.key = "separation", .unit = "length", .range = kPositive,
                                  .doc = "the spheres' initial distance"},
                        collision(&gravity::CollisionOptions::separation)));
      k.push_back(field(SourceKey{.key = "impact_parameter", .unit = "length", .range = kNonNegative,
                                  .doc = "< `separation`",
                                  .default_doc = "min(2, `separation`/5)",
                                  .context_default = [](const ParticleSource& src) -> std::optional<KeyValue> {
                                    const auto* m = std::get_if<StellarSource>(&src);
                                    if (!m) return std::nullopt;
                                    return KeyValue{std::min(2.0, 0.2 * m->collision.separation)};
                                  }},
                        collision(&gravity::CollisionOptions::impact_parameter)));
      k.push_back(field(SourceKey{.key = "relative_velocity", .unit = "length/time", .range = kNonNegative,
                                  .doc = "the spheres' initial relative speed", .default_doc = "parabolic"},
                        collision(&gravity::CollisionOptions::relative_velocity)));
      k.push_back(field(SourceKey{.key = "mass_cut", .range = kFraction, .doc = "of each sphere, as for `plummer`"},
                        collision(&gravity::CollisionOptions::mass_cut)));
      break;
    case Model::Hernquist: {
      const auto halo = [&](auto member) { return in_options(&StellarSource::hernquist, member); };
      k.push_back(field(SourceKey{.key = "scale_radius", .unit = "length", .range = kPositive,
                                  .doc = "a: the density falls as r⁻¹ inside it and r⁻⁴ outside; 1/3 gives E = −1/4 "
                                         "(Hénon units) for the whole model",
                                  .default_doc = "1/3"},
                        halo(&gravity::HernquistOptions::scale_radius)));
      k.push_back(field(SourceKey{.key = "mass_cut", .range = Range{0, 1, true, true},
                                  .doc = "the fraction of the infinite model's mass kept (0.99: out to 199 a)"},
                        halo(&gravity::HernquistOptions::mass_cut)));
      break;
    }
    case Model::Nfw: {
      const auto halo = [&](auto member) { return in_options(&StellarSource::nfw, member); };
      k.push_back(field(SourceKey{.key = "concentration", .range = Range{1, 100, false, false},
                                  .doc = "c = r_vir/r_s: the density falls as r⁻¹ inside the scale radius r_s and "
                                         "r⁻³ outside, out to r_vir"},
                        halo(&gravity::NfwOptions::concentration)));
      k.push_back(field(SourceKey{.key = "decay", .unit = "fraction of r_vir", .range = Range{0.01, 1, false, false},
                                  .doc = "r_d: beyond r_vir the density is cut off as exp(−(r − r_vir)/r_d)"},
                        halo(&gravity::NfwOptions::decay)));
      k.push_back(field(SourceKey{.key = "virial_radius", .unit = "length", .range = kPositive,
                                  .doc = "r_vir, where the cut-off starts",
                                  .default_doc = "Hénon units (E = −1/4)"},
                        halo(&gravity::NfwOptions::virial_radius)));
      break;
    }
    case Model::King:
      k.push_back(field(SourceKey{.key = "w0", .range = Range{0.1, 16, false, false},
                                  .doc = "W₀ = Ψ(0)/σ², the dimensionless central potential: 3, 6, 9 give "
                                         "concentrations log₁₀(r_t/r₀) of 0.67, 1.26, 2.12"},
                        in_options(&StellarSource::king, &gravity::KingOptions::w0)));
      break;
    case Model::DiskGalaxy: {
      const auto disk = [&](auto member) { return in_options(&StellarSource::disk, member); };
      using O = gravity::DiskGalaxyOptions;
      k.push_back(field(SourceKey{.key = "disk_mass", .unit = "mass", .range = Range{0, 1, true, true},
                                  .doc = "M_d, of a total mass 1 (the halo has 1 − M_d)"},
                        disk(&O::disk_mass)));
      k.push_back(field(SourceKey{.key = "disk_scale_length", .unit = "length", .range = kPositive,
                                  .doc = "h: Σ ∝ exp(−R/h)"},
                        disk(&O::disk_scale_length)));
      k.push_back(field(SourceKey{.key = "disk_scale_height", .unit = "length", .range = kPositive,
                                  .doc = "z₀: ρ ∝ sech²(z/z₀)"},
                        disk(&O::disk_scale_height)));
      k.push_back(field(SourceKey{.key = "disk_cut", .unit = "scale lengths", .range = Range{2, 50, false, false},
                                  .doc = "the disk's radius"},
                        disk(&O::disk_cut)));
      k.push_back(field(SourceKey{.key = "toomre_q", .range = kPositive,
                                  .doc = "Toomre's Q = σ_R κ/(3.36 GΣ) at R = 2.43 h: above 1 the disk is locally stable"},
                        disk(&O::toomre_q)));
      k.push_back(field(SourceKey{.key = "halo_scale_radius", .unit = "length", .range = kPositive,
                                  .doc = "a of the Hernquist halo"},
                        disk(&O::halo_scale_radius)));
      k.push_back(field(SourceKey{.key = "halo_mass_cut", .range = Range{0, 1, true, true},
                                  .doc = "the fraction of the halo's mass kept (0.99: out to 199 a)"},
                        disk(&O::halo_mass_cut)));
      k.push_back(field(SourceKey{.key = "disk_particles", .range = Range{0, 1, true, true},
                                  .doc = "the disk's share of `count` (the rest are the halo's)"},
                        disk(&O::disk_particles)));
      break;
    }
  }
  k.push_back(field(SourceKey{.key = "offset", .unit = "length", .doc = "moves the whole model"},
                    in_source(&StellarSource::offset)));
  k.push_back(field(SourceKey{.key = "velocity", .unit = "length/time", .doc = "the whole model's bulk velocity"},
                    in_source(&StellarSource::velocity)));
  return k;
}

std::vector<SourceKey> snapshot_keys() {
  std::vector<SourceKey> k;
  k.push_back(field(SourceKey{.key = "file",
                              .doc = "a Gadget-format HDF5 file (written by h5py, another code or swirl), relative to the scene file's "
                                     "folder; saved with a run as the absolute path it resolved to",
                              .required = true, .type_doc = "string (a path)"},
                    in_source(&SnapshotSource::file)));
  k.push_back(field(SourceKey{.key = "part_type", .range = Range{0, 5, false, false},
                              .doc = "which `/PartType<k>` group to read (one source per type)",
                              .default_doc = "the only type with particles"},
                    in_source(&SnapshotSource::part_type)));
  k.push_back(field(SourceKey{.key = "offset", .unit = "length", .doc = "moves every particle"},
                    in_source(&SnapshotSource::offset)));
  k.push_back(field(SourceKey{.key = "velocity", .unit = "length/time", .doc = "added to every particle's velocity"},
                    in_source(&SnapshotSource::velocity)));
  return k;
}

// An obstacle's keys: its shape's, then the sampling spacing.
std::vector<SourceKey> obstacle_keys(ObstacleSource::Shape shape) {
  using Shape = ObstacleSource::Shape;
  std::vector<SourceKey> k;
  const auto vector = [&](std::string_view key, Vec3d ObstacleSource::*member, std::string_view doc) {
    k.push_back(field(SourceKey{.key = key, .unit = "m", .doc = doc, .required = true}, in_source(member)));
  };
  const auto radius = [&](std::string_view doc) {
    k.push_back(field(SourceKey{.key = "radius", .unit = "m", .range = kPositive, .doc = doc, .required = true},
                      in_source(&ObstacleSource::radius)));
  };
  switch (shape) {
    case Shape::Box:
      k.push_back(region_corner("min", &Box<double>::lo, "the obstacle's low corner, inside the box"));
      k.push_back(region_corner("max", &Box<double>::hi,
                                "the high corner, inside the box, ≥ `min` on every axis (equal on one axis: a thin "
                                "plate)"));
      break;
    case Shape::Sphere:
      vector("center", &ObstacleSource::center, "the centre; the sphere lies inside the box");
      radius("the radius");
      break;
    case Shape::Cylinder:
      vector("start", &ObstacleSource::start, "the centre of one end disc");
      vector("end", &ObstacleSource::end, "the centre of the other end disc (≠ `start`); the cylinder lies inside the box");
      radius("the radius");
      break;
    case Shape::Plane:
      vector("point", &ObstacleSource::point, "a point of the plane, inside the box");
      k.push_back(field(SourceKey{.key = "normal", .doc = "its normal (any length > 0); the plane is clipped to the box"},
                        in_source(&ObstacleSource::normal)));
      break;
    case Shape::Mesh:
      k.push_back(field(SourceKey{.key = "file",
                                  .doc = "an STL (ASCII or binary) or OBJ file of triangles, relative to the scene "
                                         "file's folder; saved with a run as the absolute path it resolved to",
                                  .required = true, .type_doc = "string (a path)"},
                        in_source(&ObstacleSource::file)));
      k.push_back(field(SourceKey{.key = "scale", .range = kPositive,
                                  .doc = "multiplies the file's coordinates (0.001: a file in mm)"},
                        in_source(&ObstacleSource::scale)));
      k.push_back(field(SourceKey{.key = "rotate_deg", .unit = "degrees",
                                  .doc = "turns the scaled mesh about the x, then the y, then the z axis (right-handed, "
                                         "about the origin)"},
                        in_source(&ObstacleSource::rotate_deg)));
      k.push_back(field(SourceKey{.key = "translate", .unit = "m",
                                  .doc = "then moves it; the placed mesh lies inside the box"},
                        in_source(&ObstacleSource::translate)));
      break;
  }
  k.push_back(field(SourceKey{.key = "spacing", .unit = "m", .range = kPositive,
                              .doc = "the distance between its boundary particles",
                              .default_doc = "the first `fluid_block`'s spacing", .custom_read = true},
                    in_source(&ObstacleSource::spacing)));
  // Absent (empty) it is not in the hash: scenes from before the key keep theirs.
  SourceKey name{.key = "name", .type = KeyType::Text,
                 .doc = "its name in `probes.csv` (`output.obstacle_forces`): letters, digits and `_`, unique among "
                        "the obstacles and probes",
                 .default_doc = "`\"obstacle<k>\"`, k = 1, 2, ... over the obstacles in order"};
  name.get = [](const ParticleSource& src) -> std::optional<KeyValue> {
    const auto* o = std::get_if<ObstacleSource>(&src);
    if (!o || o->name.empty()) return std::nullopt;
    return KeyValue{std::string_view(o->name)};
  };
  name.set = [](ParticleSource& src, const KeyValue& v) {
    if (auto* o = std::get_if<ObstacleSource>(&src)) o->name = std::string(std::get<std::string_view>(v));
  };
  k.push_back(std::move(name));
  // The `motion` table (boundary/rigid_motion.hpp), read by hand: its kind
  // says which of the keys below it takes. Absent: a static obstacle, and
  // none of them is in the hash.
  constexpr unsigned kPiston = 1, kFlap = 2, kRotation = 4, kAnyMotion = 7;
  const auto motion = [&](SourceKey spec, auto member, unsigned kinds) {
    spec.custom_read = true;
    k.push_back(field(std::move(spec), in_motion(member, kinds)));
  };
  motion({.key = "motion.kind", .noun = "motion",
          .doc = "a prescribed rigid motion of the obstacle as placed above (its rest position; docs/sph.md, Moving "
                 "obstacles): `\"piston\"` (a translation), `\"flap\"` (an oscillating rotation about a hinge) or "
                 "`\"rotation\"` (a steady one); its particles are put at the motion's x and v before every force "
                 "evaluation (grid search; on several MPI ranks too)",
          .default_doc = "– (static)"},
         &boundary::RigidMotion::kind, kAnyMotion);
  motion({.key = "motion.direction",
          .doc = "piston: the stroke's direction (any length > 0): the shift is A·r(τ)·sin(2πfτ + φ) along it, τ = "
                 "t − `motion.start`",
          .required = true},
         &boundary::RigidMotion::direction, kPiston);
  motion({.key = "motion.amplitude", .unit = "m", .range = kPositive, .doc = "piston: A, half the stroke",
          .required = true},
         &boundary::RigidMotion::amplitude, kPiston);
  motion({.key = "motion.amplitude_deg", .unit = "degrees", .range = Range{0, 180, true, false},
          .doc = "flap: θ_A: the angle about `motion.axis` is θ_A·r(τ)·sin(2πfτ + φ)", .required = true},
         &boundary::RigidMotion::amplitude_deg, kFlap);
  motion({.key = "motion.frequency", .unit = "Hz", .range = kPositive, .doc = "piston, flap: f", .required = true},
         &boundary::RigidMotion::frequency, kPiston | kFlap);
  motion({.key = "motion.phase_deg", .unit = "degrees", .doc = "piston, flap: φ (≠ 0 without a ramp: the obstacle "
                                                                "starts displaced)",
          .default_doc = "`0`"},
         &boundary::RigidMotion::phase_deg, kPiston | kFlap);
  motion({.key = "motion.axis",
          .doc = "flap, rotation: the hinge's or the shaft's direction (any length > 0; angles right-handed about it)",
          .required = true},
         &boundary::RigidMotion::axis, kFlap | kRotation);
  motion({.key = "motion.point", .unit = "m", .doc = "flap, rotation: a point on the axis", .required = true},
         &boundary::RigidMotion::point, kFlap | kRotation);
  motion({.key = "motion.angular_velocity", .unit = "rad/s",
          .doc = "rotation: ω0 ≠ 0; the angle is ω0·∫₀^τ r", .required = true},
         &boundary::RigidMotion::angular_velocity, kRotation);
  motion({.key = "motion.start", .unit = "s", .range = kNonNegative,
          .doc = "the motion starts at this time; before it the obstacle rests (at its pose for τ = 0)",
          .default_doc = "`0`"},
         &boundary::RigidMotion::start, kAnyMotion);
  motion({.key = "motion.ramp", .unit = "s", .range = kNonNegative,
          .doc = "T: the motion eases in as r(τ) = (1 − cos(πτ/T))/2 for τ < T, 1 after, so that x and v are "
                 "continuous; 0: r = 1, the velocity jumps at `motion.start`",
          .default_doc = "`0`"},
         &boundary::RigidMotion::ramp, kAnyMotion);
  return k;
}

// A fluid fill's keys (fluid_sphere, fluid_mesh): its shape's, then the lattice and the velocity.
std::vector<SourceKey> fill_keys(FluidFillSource::Shape shape) {
  std::vector<SourceKey> k;
  if (shape == FluidFillSource::Shape::Sphere) {
    k.push_back(field(SourceKey{.key = "center", .unit = "m", .doc = "the centre; the sphere lies inside the box",
                                .required = true},
                      in_source(&FluidFillSource::center)));
    k.push_back(field(SourceKey{.key = "radius", .unit = "m", .range = kPositive, .doc = "the radius", .required = true},
                      in_source(&FluidFillSource::radius)));
  } else {
    k.push_back(field(SourceKey{.key = "file",
                                .doc = "a closed STL (ASCII or binary) or OBJ surface of triangles, relative to the "
                                       "scene file's folder (every edge in two triangles, consistently oriented); "
                                       "saved with a run as the absolute path it resolved to",
                                .required = true, .type_doc = "string (a path)"},
                      in_source(&FluidFillSource::file)));
    k.push_back(field(SourceKey{.key = "scale", .range = kPositive,
                                .doc = "multiplies the file's coordinates (0.001: a file in mm)"},
                      in_source(&FluidFillSource::scale)));
    k.push_back(field(SourceKey{.key = "rotate_deg", .unit = "degrees",
                                .doc = "turns the scaled mesh about the x, then the y, then the z axis (right-handed, "
                                       "about the origin)"},
                      in_source(&FluidFillSource::rotate_deg)));
    k.push_back(field(SourceKey{.key = "translate", .unit = "m",
                                .doc = "then moves it; the placed mesh lies inside the box"},
                      in_source(&FluidFillSource::translate)));
  }
  k.push_back(field(SourceKey{.key = "spacing", .unit = "m", .range = kPositive,
                              .doc = "the lattice constant (the fluid_block's lattice over the shape's bounding box; "
                                     "the points inside are kept)",
                              .required = true},
                    in_source(&FluidFillSource::spacing)));
  k.push_back(velocity_key<FluidFillSource>("the initial velocity of every particle"));
  return k;
}

std::vector<SourceKind> declare_source_kinds() {
  std::vector<SourceKind> kinds;
  kinds.push_back({"lattice", "particles on a cubic lattice filling a region", lattice_keys(false), LatticeSource{}});
  kinds.push_back({"random", "uniformly random positions in a region", random_keys(), RandomSource{}});
  kinds.push_back({"list", "particles given one by one", list_keys(), ListSource{}});
  kinds.push_back({"fluid_block",
                   "a lattice whose mass makes an interior particle's SPH density exactly `sph.rest_density` (needs "
                   "`[sph]`)",
                   lattice_keys(true), LatticeSource{}});
  for (const auto& shape : kFluidFillShapeNames) {
    FluidFillSource prototype;
    prototype.shape = shape.value;
    static constexpr std::string_view docs[] = {
        "the fluid_block's lattice inside a sphere, at the same mass (needs `[sph]`)",
        "the fluid_block's lattice inside a closed STL or OBJ surface (generalised winding number), at the same mass "
        "(needs `[sph]`; docs/sph.md)"};
    kinds.push_back({shape.name, docs[static_cast<std::size_t>(shape.value)], fill_keys(shape.value), prototype});
  }
  for (const auto& model : kStellarModelNames) {
    StellarSource prototype;
    prototype.model = model.value;
    kinds.push_back({model.name, "a self-gravitating model (open space only)", stellar_keys(model.value), prototype});
  }
  kinds.push_back({"snapshot",
                   "particles read from a Gadget-format HDF5 file: a swirl `hdf5` frame, or initial conditions from "
                   "another code",
                   snapshot_keys(), SnapshotSource{}});
  for (const auto& shape : kObstacleShapeNames) {
    ObstacleSource prototype;
    prototype.shape = shape.value;
    static constexpr std::string_view docs[] = {
        "a static box obstacle: its surface sampled by boundary particles (needs `[sph]`, grid search)",
        "a static sphere: its surface sampled by boundary particles (needs `[sph]`, grid search)",
        "a static closed cylinder: side and end discs sampled by boundary particles (needs `[sph]`, grid search)",
        "a static plane clipped to the box (a wall across it), sampled by boundary particles (needs `[sph]`, grid "
        "search)",
        "a static triangle mesh from an STL or OBJ file: its vertices, edges and faces sampled by boundary particles "
        "at most a spacing apart (docs/sph.md; needs `[sph]`, grid search)"};
    kinds.push_back({shape.name, docs[static_cast<std::size_t>(shape.value)], obstacle_keys(shape.value), prototype});
  }
  // Each key's docs table is its kind.
  for (auto& kind : kinds)
    for (auto& key : kind.keys) key.section = kind.name;
  return kinds;
}

using ProbeKey = KeySpec<Probe>;

std::vector<ProbeKey> declare_probe_keys() {
  std::vector<ProbeKey> k;
  k.push_back(field(ProbeKey{.key = "name", .section = "probes",
                             .doc = "the probe's name, the start of its columns in `probes.csv`: letters, digits and "
                                    "`_`, unique among the probes and obstacles",
                             .required = true},
                    [](auto& p) { return &p.name; }));
  k.push_back(field(ProbeKey{.key = "point", .section = "probes", .unit = "m",
                             .doc = "a pressure probe here, inside the box: column `<name>_pressure` (Pa), the "
                                    "Shepard-normalised kernel interpolation of the fluid particles' pressures",
                             .default_doc = "–"},
                    [](auto& p) { return &p.point; }));
  ProbeKey line{.key = "line", .section = "probes", .type = KeyType::VectorList, .unit = "m",
                .doc = "`[[x, y, z0], [x, y, z1]]`, z0 < z1, inside the box: a vertical water-height gauge, column "
                       "`<name>_height` (m above z0), where the fluid's kernel sum Σ V_j W falls below 0.5; give "
                       "`point` or `line`",
                .default_doc = "–", .custom_read = true};
  line.get = [](const Probe& p) -> std::optional<KeyValue> {
    if (p.line.empty()) return std::nullopt;
    return KeyValue{p.line};
  };
  line.set = [](Probe& p, const KeyValue& v) { p.line = std::get<std::vector<Vec3d>>(v); };
  k.push_back(std::move(line));
  return k;
}

using InletKey = KeySpec<Inlet>;
using OutletKey = KeySpec<Outlet>;

std::vector<InletKey> declare_inlet_keys() {
  std::vector<InletKey> k;
  k.push_back(field(InletKey{.key = "center", .section = "inlets", .unit = "m",
                             .doc = "the centre of the inlet's disc, inside the box", .required = true},
                    [](auto& i) { return &i.center; }));
  k.push_back(field(InletKey{.key = "direction", .section = "inlets",
                             .doc = "the direction the fluid leaves the disc in (any length > 0); the disc is "
                                    "perpendicular to it",
                             .required = true},
                    [](auto& i) { return &i.direction; }));
  k.push_back(field(InletKey{.key = "radius", .section = "inlets", .unit = "m", .range = kPositive,
                             .doc = "the disc's radius", .required = true},
                    [](auto& i) { return &i.radius; }));
  k.push_back(field(InletKey{.key = "speed", .section = "inlets", .unit = "m/s", .range = kPositive,
                             .doc = "the speed of the entering fluid along `direction`", .required = true},
                    [](auto& i) { return &i.speed; }));
  k.push_back(field(InletKey{.key = "spacing", .section = "inlets", .unit = "m", .range = kPositive,
                             .doc = "the distance between its particles across the disc and between its layers "
                                    "(a layer every spacing/speed: the fluid enters at the rest density); the "
                                    "mass per particle is a fluid_block's at this spacing",
                             .required = true},
                    [](auto& i) { return &i.spacing; }));
  k.push_back(field(InletKey{.key = "start", .section = "inlets", .unit = "s", .range = kNonNegative,
                             .doc = "when the first layer leaves the disc"},
                    [](auto& i) { return &i.start; }));
  k.push_back(field(InletKey{.key = "stop", .section = "inlets", .unit = "s", .range = kPositive,
                             .doc = "no layer leaves at or after this time (> `start`)",
                             .default_doc = "never"},
                    [](auto& i) { return &i.stop; }));
  return k;
}

std::vector<OutletKey> declare_outlet_keys() {
  std::vector<OutletKey> k;
  k.push_back(field(OutletKey{.key = "min", .section = "outlets", .unit = "m",
                              .doc = "the outlet box's low corner (it may reach outside the scene's box)",
                              .required = true},
                    [](auto& o) { return &o.region.lo; }));
  k.push_back(field(OutletKey{.key = "max", .section = "outlets", .unit = "m",
                              .doc = "its high corner, greater than `min` on every axis; fluid particles inside are "
                                     "removed after every step",
                              .required = true},
                    [](auto& o) { return &o.region.hi; }));
  return k;
}

const std::vector<InletKey>& inlet_key_list() {
  static const std::vector<InletKey> keys = declare_inlet_keys();
  return keys;
}

const std::vector<OutletKey>& outlet_key_list() {
  static const std::vector<OutletKey> keys = declare_outlet_keys();
  return keys;
}

const std::vector<ProbeKey>& probe_key_list() {
  static const std::vector<ProbeKey> keys = declare_probe_keys();
  return keys;
}

const std::vector<SceneKey>& scene_key_list() {
  static const std::vector<SceneKey> keys = declare_scene_keys();
  return keys;
}

const std::vector<SourceKind>& source_kind_list() {
  static const std::vector<SourceKind> kinds = declare_source_kinds();
  return kinds;
}

// ---- The docs' tables --------------------------------------------------------

std::string_view type_text(KeyType type) {
  switch (type) {
    case KeyType::Number: return "number";
    case KeyType::Integer: return "integer";
    case KeyType::Boolean: return "boolean";
    case KeyType::Name: return "string";
    case KeyType::NameList: return "array of strings";
    case KeyType::Vector: return "vector";
    case KeyType::VectorList: return "array of vectors";
    case KeyType::NumberList: return "array of numbers";
    case KeyType::Text: return "string";
  }
  return "?";
}

// The constraint column: the range or the names, then the doc line.
template <class Owner>
std::string constraint_text(const KeySpec<Owner>& spec) {
  std::string rule;
  if (spec.type == KeyType::Number || spec.type == KeyType::NumberList || spec.type == KeyType::Vector ||
      spec.type == KeyType::VectorList)
    rule = "finite";
  std::string range = spec.range.text();
  if (!range.empty() && spec.type != KeyType::Vector && spec.type != KeyType::VectorList) {
    // ">= 0" reads better as "≥ 0" in prose.
    for (auto at = range.find(">="); at != std::string::npos; at = range.find(">=")) range.replace(at, 2, "≥");
    for (auto at = range.find("<="); at != std::string::npos; at = range.find("<=")) range.replace(at, 2, "≤");
    rule += (rule.empty() ? "" : ", ") + range;
  }
  if (!spec.names.empty()) {
    std::string names;
    for (std::size_t i = 0; i < spec.names.size(); ++i)
      names += fmt::format("{}`\"{}\"`", i == 0 ? "" : i + 1 == spec.names.size() ? " or " : ", ", spec.names[i]);
    // A name key's doc already explains each name when it quotes them.
    if (spec.doc.find("`\"") == std::string_view::npos) rule += (rule.empty() ? "" : ", ") + names;
  }
  if (rule.empty()) return std::string(spec.doc);
  return fmt::format("{}: {}", rule, spec.doc);
}

template <class Owner>
std::string default_text(const KeySpec<Owner>& spec, const Owner& defaults) {
  if (!spec.default_doc.empty()) return std::string(spec.default_doc);
  if (spec.required) return "required";
  const auto value = spec.get ? spec.get(defaults) : std::nullopt;
  if (!value) return "–";
  return fmt::format("`{}`", value_text(*value, false));
}

template <class Owner>
std::string row(const KeySpec<Owner>& spec, std::string_view shown_key, const Owner& defaults) {
  const std::string type = spec.type_doc.empty() ? std::string(type_text(spec.type)) : std::string(spec.type_doc);
  return fmt::format("| `{}` | {} | {} | {} | {} |\n", shown_key, type, spec.unit.empty() ? "–" : spec.unit,
                     default_text(spec, defaults), constraint_text(spec));
}

constexpr std::string_view kTableHeader = "| key | type | unit | default | constraint |\n|---|---|---|---|---|\n";

// Every section with its fields present, so that each key's default shows.
Scene scene_with_every_section() {
  Scene s;
  s.sph.emplace();
  s.nbody.emplace();
  s.random_box = Scene::RandomBox{};
  return s;
}

constexpr std::string_view kRegionOpen = "<!-- scene-keys:";
constexpr std::string_view kRegionOpenEnd = " (generated by scene_keys_doc; do not edit) -->\n";
constexpr std::string_view kRegionClose = "<!-- /scene-keys -->";

}  // namespace

std::span<const KeySpec<Scene>> scene_keys() { return scene_key_list(); }

std::span<const KeySpec<Probe>> probe_keys() { return probe_key_list(); }
std::span<const KeySpec<Inlet>> inlet_keys() { return inlet_key_list(); }
std::span<const KeySpec<Outlet>> outlet_keys() { return outlet_key_list(); }

std::span<const std::string_view> scene_sections() {
  static constexpr std::string_view sections[] = {"simulation", "box",    "forces",    "sph",   "random_box",
                                                  "nbody",      "output", "particles", "probes",
                                                  "inlets",     "outlets"};
  return sections;
}

std::span<const SourceKind> source_kinds() { return source_kind_list(); }

const SourceKind& kind_of(const ParticleSource& source) {
  // The first kind of the same alternative (and model): a LatticeSource is a
  // "lattice", declared before "fluid_block".
  const auto same = [&](const SourceKind& kind) {
    if (kind.prototype.index() != source.index()) return false;
    if (const auto* obstacle = std::get_if<ObstacleSource>(&source))
      return std::get<ObstacleSource>(kind.prototype).shape == obstacle->shape;
    if (const auto* fill = std::get_if<FluidFillSource>(&source))
      return std::get<FluidFillSource>(kind.prototype).shape == fill->shape;
    const auto* model = std::get_if<StellarSource>(&source);
    return !model || std::get<StellarSource>(kind.prototype).model == model->model;
  };
  const auto& kinds = source_kind_list();
  const auto it = std::find_if(kinds.begin(), kinds.end(), same);
  if (it == kinds.end()) throw std::logic_error("a particle source of no declared kind");
  return *it;
}

namespace {

// `text` as a TOML basic string: `"` and `\` escaped, and every control
// character, so that any path reads back as itself.
std::string toml_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\b': out += "\\b"; break;
      case '\t': out += "\\t"; break;
      case '\n': out += "\\n"; break;
      case '\f': out += "\\f"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
          out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        else
          out += c;
    }
  }
  return out + "\"";
}

}  // namespace

std::string value_text(const KeyValue& value, bool exact) {
  const auto number = [exact](double v) { return exact ? fmt::format("{:.17g}", v) : fmt::format("{}", v); };
  const auto vec = [&](const Vec3d& v) { return fmt::format("[{}, {}, {}]", number(v.x), number(v.y), number(v.z)); };
  return std::visit(
      [&]<class T>(const T& v) -> std::string {
        if constexpr (std::is_same_v<T, double>) return number(v);
        else if constexpr (std::is_same_v<T, std::uint64_t>) return fmt::format("{}", v);
        else if constexpr (std::is_same_v<T, bool>) return v ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::string_view>) return toml_string(v);
        else if constexpr (std::is_same_v<T, Vec3d>) return vec(v);
        else {
          std::string out = "[";
          for (std::size_t i = 0; i < v.size(); ++i) {
            out += i ? ", " : "";
            if constexpr (std::is_same_v<T, std::vector<std::string_view>>) out += toml_string(v[i]);
            else if constexpr (std::is_same_v<T, std::vector<Vec3d>>) out += vec(v[i]);
            else out += number(v[i]);
          }
          return out + "]";
        }
      },
      value);
}

std::vector<std::string_view> key_table_sections() {
  std::vector<std::string_view> out(scene_sections().begin(), scene_sections().end());
  out.insert(out.begin(), "format");
  for (const auto& kind : source_kinds()) out.push_back(kind.name);
  return out;
}

std::string key_table_markdown(std::string_view section) {
  std::string out(kTableHeader);
  if (section == "particles") {
    std::string kinds;
    for (std::size_t i = 0; i < source_kinds().size(); ++i)
      kinds += fmt::format("{}`\"{}\"`", i ? ", " : "", source_kinds()[i].name);
    return out + fmt::format("| `kind` | string | – | required | {}: the kind of source, below |\n", kinds);
  }
  if (section == "probes") {
    for (const auto& spec : probe_keys()) out += row(spec, spec.key, Probe{});
    return out;
  }
  if (section == "inlets") {
    for (const auto& spec : inlet_keys()) out += row(spec, spec.key, Inlet{});
    return out;
  }
  if (section == "outlets") {
    for (const auto& spec : outlet_keys()) out += row(spec, spec.key, Outlet{});
    return out;
  }
  for (const auto& kind : source_kinds()) {
    if (kind.name != section) continue;
    for (const auto& spec : kind.keys) out += row(spec, spec.key, kind.prototype);
    return out;
  }
  // A section of the scene; "format" stands for the root keys' table.
  const bool root = section == "format";
  if (!root && std::ranges::find(scene_sections(), section) == scene_sections().end())
    throw std::runtime_error(fmt::format("no scene key table '{}'", section));
  const std::string_view table = root ? std::string_view() : section;
  const Scene defaults = scene_with_every_section();
  for (const auto& spec : scene_keys()) {
    if (spec.section != table) continue;
    std::string_view shown = spec.key;
    if (shown.starts_with(section) && shown.size() > section.size() && shown[section.size()] == '.')
      shown.remove_prefix(section.size() + 1);
    out += row(spec, shown, defaults);
  }
  return out;
}

std::string with_generated_key_tables(std::string_view markdown) {
  std::string out;
  std::vector<std::string_view> seen;
  std::size_t at = 0;
  for (;;) {
    const std::size_t open = markdown.find(kRegionOpen, at);
    if (open == std::string_view::npos) break;
    const std::size_t name_start = open + kRegionOpen.size();
    const std::size_t name_end = markdown.find(kRegionOpenEnd, name_start);
    if (name_end == std::string_view::npos || markdown.substr(name_start, name_end - name_start).find('\n') != std::string_view::npos)
      throw std::runtime_error(fmt::format("malformed region start at byte {}", open));
    const std::string_view section = markdown.substr(name_start, name_end - name_start);
    const std::size_t body = name_end + kRegionOpenEnd.size();
    const std::size_t close = markdown.find(kRegionClose, body);
    if (close == std::string_view::npos) throw std::runtime_error(fmt::format("region '{}' is not closed", section));
    out += markdown.substr(at, body - at);
    out += key_table_markdown(section);  // throws for an unknown section
    seen.push_back(section);
    at = close;
  }
  out += markdown.substr(at);
  for (const auto section : key_table_sections())
    if (std::ranges::find(seen, section) == seen.end())
      throw std::runtime_error(fmt::format("no generated region for the key table '{}'", section));
  return out;
}

}  // namespace swirl::scene
