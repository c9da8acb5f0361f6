// Scene: the typed, validated description of one simulation, made from a TOML
// scene file by load_scene() or built in code and checked by validate()
// (scene/validate.hpp). A solver never sees TOML; it sees this.
//
// Units: `units` says which system the numbers are in, SI (m, s, kg) or
// N-body units (G = 1 unless nbody.G says otherwise); gravitational_constant is
// the resolved G. A loaded scene has passed validation: dt > 0, a valid box,
// restitution in [0, 1], at least one particle, all particles inside the box
// (when the scene has walls). Each key's name, unit, default and range are
// declared once, in scene/keys.hpp; the defaults are the member initialisers here.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "swirl/boundary/rigid_motion.hpp"
#include "swirl/core/box.hpp"
#include "swirl/core/enum_names.hpp"
#include "swirl/core/vec3.hpp"
#include "swirl/gravity/disk_galaxy.hpp"
#include "swirl/gravity/initial_conditions.hpp"
#include "swirl/gravity/settings.hpp"
#include "swirl/gravity/spherical_models.hpp"
#include "swirl/io/mesh_file.hpp"
#include "swirl/sph/parameters.hpp"

namespace swirl::scene {

enum class Precision { Float, Double };
enum class OutputFormat { Vtp, Csv, Hdf5 };
// output.surface: the fluid's surface mesh per frame (render/surface_mesh.hpp), or none.
enum class SurfaceFormat { None, Ply, Obj };
// The unit system of a scene's numbers: SI (m, s, kg; G = 6.67430e-11
// m³ kg⁻¹ s⁻²) or N-body units (G = 1, Hénon units for the stellar models).
enum class Units { SI, NBody };
// simulation.time_steps: one step for every particle, or individual
// power-of-two bins below it (integrate/block_steps.hpp).
enum class TimeSteps { Global, Block };

inline constexpr std::array<EnumName<Precision>, 2> kPrecisionNames{{{"float", Precision::Float}, {"double", Precision::Double}}};
inline constexpr std::array<EnumName<OutputFormat>, 3> kOutputFormatNames{
    {{"vtp", OutputFormat::Vtp}, {"csv", OutputFormat::Csv}, {"hdf5", OutputFormat::Hdf5}}};
inline constexpr std::array<EnumName<SurfaceFormat>, 3> kSurfaceFormatNames{
    {{"none", SurfaceFormat::None}, {"ply", SurfaceFormat::Ply}, {"obj", SurfaceFormat::Obj}}};
inline constexpr std::array<EnumName<Units>, 2> kUnitsNames{{{"si", Units::SI}, {"nbody", Units::NBody}}};
inline constexpr std::array<EnumName<TimeSteps>, 2> kTimeStepsNames{
    {{"global", TimeSteps::Global}, {"block", TimeSteps::Block}}};

// The gravitational constant in SI units, m³ kg⁻¹ s⁻² (CODATA 2018).
inline constexpr double kGravitationalConstantSI = 6.67430e-11;

// The scene file format this build reads and writes (the root key `format`).
// A file without the key is of this format; a newer one is refused.
inline constexpr std::uint32_t kSceneFormatVersion = 1;

// Particles on a simple cubic lattice filling `region`: one at the centre of
// every spacing-sized cell that fits wholly inside the region, i.e.
// floor(extent / spacing) points per axis at region.lo + spacing·(i + ½)
// (docs/scenes.md gives the exact rule), each moved by a uniform random offset
// of up to jitter·spacing per axis.
struct LatticeSource {
  Box<double> region;
  double spacing = 0;       // lattice constant, > 0
  double jitter = 0;        // fraction of spacing, in [0, 0.5)
  std::uint64_t seed = 1;   // for the jitter
  double mass = 0;          // per particle, > 0
  Vec3d velocity{};         // initial velocity of every particle
};

// A fluid filling a sphere or a closed triangle mesh (kinds "fluid_sphere",
// "fluid_mesh"), by the fluid_block's lattice rule applied to the shape's
// bounding box B: floor(extent_a / spacing) points per axis at
// B.lo + spacing·(i + ½), of which those inside the shape are kept (a sphere:
// |x − center| < radius; a mesh: generalised winding number |w| ≥ ½,
// scene/fluid_fill.hpp). B is [center − radius, center + radius] for a sphere
// and the placed vertices' bounding box for a mesh, so a mesh cube gives
// exactly the fluid_block of the same corners. The mass (kg per particle) is
// the fluid_block's, set by load_scene from [sph] (a Scene built in code
// sets it). The mesh must be closed and consistently oriented (every edge in
// exactly two triangles, once in each direction).
struct FluidFillSource {
  enum class Shape { Sphere, Mesh };
  Shape shape = Shape::Sphere;
  Vec3d center{};           // sphere: its centre (m)
  double radius = 0;        // sphere: its radius (m, > 0)
  double spacing = 0;       // lattice constant (m, > 0)
  double mass = 0;          // per particle (kg, > 0)
  Vec3d velocity{};         // initial velocity of every particle (m/s)
  // mesh: the file and its placement, as an obstacle_mesh's: x' = R·(scale·x) + translate.
  std::string file;
  double scale = 1;
  Vec3d rotate_deg{};
  Vec3d translate{};
  std::shared_ptr<const io::TriangleMesh> mesh;  // filled by load_scene (as ObstacleSource::mesh)
};

inline constexpr std::array<EnumName<FluidFillSource::Shape>, 2> kFluidFillShapeNames{{
    {"fluid_sphere", FluidFillSource::Shape::Sphere},
    {"fluid_mesh", FluidFillSource::Shape::Mesh},
}};

// `count` particles placed uniformly at random in `region`.
struct RandomSource {
  Box<double> region;
  std::size_t count = 0;
  std::uint64_t seed = 1;
  double mass = 0;
  Vec3d velocity{};
};

// Particles given one by one.
struct ListSource {
  std::vector<Vec3d> positions;
  std::vector<Vec3d> velocities;  // empty (all at rest) or one per position
  std::vector<double> masses;     // one per position
};

// A self-gravitating model from gravity/initial_conditions.hpp,
// gravity/spherical_models.hpp or gravity/disk_galaxy.hpp (G = 1 units),
// moved by `offset` and given the extra bulk `velocity`.
struct StellarSource {
  enum class Model { Plummer, UniformSphere, UniformCube, ColdCollapse, PlummerCollision, Hernquist, Nfw, King, DiskGalaxy };
  Model model = Model::Plummer;
  std::size_t count = 0;
  std::uint64_t seed = 1;
  double size = 1;   // uniform_sphere: radius; uniform_cube: side
  double mass = 1;   // uniform_sphere, uniform_cube: total mass
  gravity::PlummerOptions plummer;      // plummer
  gravity::CollisionOptions collision;  // plummer_collision
  gravity::HernquistOptions hernquist;  // hernquist
  gravity::NfwOptions nfw;              // nfw
  gravity::KingOptions king;            // king
  gravity::DiskGalaxyOptions disk;      // disk_galaxy
  Vec3d offset{};
  Vec3d velocity{};
};

// The stellar models' names, which are also their [[particles]] kinds.
inline constexpr std::array<EnumName<StellarSource::Model>, 9> kStellarModelNames{{
    {"plummer", StellarSource::Model::Plummer},
    {"uniform_sphere", StellarSource::Model::UniformSphere},
    {"uniform_cube", StellarSource::Model::UniformCube},
    {"cold_collapse", StellarSource::Model::ColdCollapse},
    {"plummer_collision", StellarSource::Model::PlummerCollision},
    {"hernquist", StellarSource::Model::Hernquist},
    {"nfw", StellarSource::Model::Nfw},
    {"king", StellarSource::Model::King},
    {"disk_galaxy", StellarSource::Model::DiskGalaxy},
}};

// What a snapshot source's file held, as read when the scene was loaded: its
// particles in file order (in double, exact for float and double files) and
// what the file says of its units, for validate() to compare with the scene's.
struct SnapshotContent {
  std::string group;                 // "/PartType1": the group read, for messages
  std::vector<Vec3d> positions;      // Coordinates
  std::vector<Vec3d> velocities;     // Velocities (zero when the file has none)
  std::vector<double> masses;        // Masses, or the header's MassTable entry
  std::string unit_system;           // /Header/UnitSystem ("si", "nbody"); "" when absent
  std::optional<std::array<double, 3>> cgs_units;  // /Units U_L, U_M, U_t (cm, g, s); nullopt when absent
};

// Particles read from a Gadget-format HDF5 file (io/snapshot.hpp), one per row
// of /PartType<part_type>, moved by `offset` and given the extra `velocity`.
struct SnapshotSource {
  std::string file;                        // an absolute, lexically normal path once loaded (load_scene
                                           // resolves a relative one against the scene file's folder)
  std::optional<std::uint64_t> part_type;  // 0 to 5; nullopt: the only type the file has particles of
  Vec3d offset{};
  Vec3d velocity{};
  // Filled by load_scene, which reads the file; shared by copies of the Scene.
  // A Scene built in code must fill it too (validate() refuses a source without it).
  std::shared_ptr<const SnapshotContent> content;
};

// A static obstacle, sampled by one layer of boundary particles (Akinci et
// al. 2012; core/particle_kind.hpp) at `spacing` (default: the first
// fluid_block's): the surface of a box (a box of zero extent along one axis
// is a thin plate), of a sphere, of a closed cylinder (side and end discs), a
// plane clipped to the scene's box, or the triangles of an STL or OBJ file.
// Needs [sph] with the grid search.
// Sampling (scene/initial_conditions.hpp, obstacle_points()): a box's surface
// is the lattice points of [min, max] with n_a = round(extent_a / spacing)
// intervals per axis that lie on a face; a sphere's is a Fibonacci lattice of
// round(4πr²/spacing²) points; a cylinder's is round(L/spacing) + 1 rings of
// round(2πr/spacing) points along the axis and concentric rings on the end
// discs; a plane's is a square lattice through `point` inside the box; a
// mesh's is its vertices, its edges and its triangles' insides at most a
// spacing apart (mesh_points(), scene/mesh_sampling.hpp).
struct ObstacleSource {
  enum class Shape { Box, Sphere, Cylinder, Plane, Mesh };
  Shape shape = Shape::Box;
  Box<double> region;       // box: min, max (m)
  Vec3d center{};           // sphere: its centre (m)
  double radius = 0;        // sphere, cylinder (m, > 0)
  Vec3d start{}, end{};     // cylinder: the centres of its end discs (m)
  Vec3d point{};            // plane: a point on it (m)
  Vec3d normal{0, 0, 1};    // plane: its normal (any length > 0)
  double spacing = 0;       // m, > 0 once loaded (load_scene: the first fluid_block's when not given)
  Box<double> clip;         // plane: the box it is clipped to (load_scene: the scene's box)
  // mesh: the file (an absolute, lexically normal path once loaded, as a
  // snapshot's), and how its vertices are placed: x' = R·(scale·x) + translate,
  // R the rotation about x, then y, then z by rotate_deg's three angles.
  std::string file;
  double scale = 1;
  Vec3d rotate_deg{};
  Vec3d translate{};
  // mesh: the triangles as the file gives them (before scale, rotation and
  // translation). Filled by load_scene, which reads the file; shared by copies
  // of the Scene. A Scene built in code must fill it too (validate() refuses a
  // mesh without it).
  std::shared_ptr<const io::TriangleMesh> mesh;
  // Its name in probes.csv (output.obstacle_forces); empty: "obstacle<k>", k
  // counting the scene's obstacles from 1 in source order.
  std::string name;
  // The `motion` table: a prescribed rigid motion (a piston, a flap, a
  // rotating paddle; boundary/rigid_motion.hpp) of the obstacle as placed
  // above, its rest position; none: static. Validation keeps its swept
  // particles inside the box (when the scene has one).
  std::optional<boundary::RigidMotion> motion;
};

// The point about which an obstacle's torque is taken (probes.csv): the
// centre of its box, its sphere's centre, the middle of its cylinder's axis,
// its plane's point, a mesh's origin as placed (translate).
inline Vec3d obstacle_centre(const ObstacleSource& o) {
  switch (o.shape) {
    case ObstacleSource::Shape::Box: return (o.region.lo + o.region.hi) * 0.5;
    case ObstacleSource::Shape::Sphere: return o.center;
    case ObstacleSource::Shape::Cylinder: return (o.start + o.end) * 0.5;
    case ObstacleSource::Shape::Plane: return o.point;
    case ObstacleSource::Shape::Mesh: return o.translate;
  }
  return o.point;
}

// A probe ([[probes]]; docs/sph.md, Probes): a named point where the SPH
// interpolation of the fluid's pressure is recorded, or a vertical line along
// which the water height is found, written to probes.csv in the run folder.
struct Probe {
  std::string name;            // [A-Za-z0-9_]+, unique among the probes and obstacles
  std::optional<Vec3d> point;  // a point probe: where (m)
  std::vector<Vec3d> line;     // a line probe: its lower and upper end (m), same x and y; empty otherwise
};

// An inlet ([[inlets]]; docs/sph.md, Inlets and outlets): a disc of `radius`
// about `center`, facing `direction`, through which fluid particles enter at
// `speed` along it. Its particles sit on a square lattice of the inlet's
// `spacing` in the disc's plane (the points a·s·u + b·s·v, a and b integers,
// strictly within the radius; u, v the disc's axes); a new layer leaves it
// every spacing/speed of simulated time from `start` on (layer k at
// start + k·spacing/speed), so the fluid enters at the rest density, and none
// after `stop`. A layer is added after the step that reaches its time, moved
// the distance it has travelled since. Mass per particle: the fluid_block's
// at the inlet's spacing (load_scene sets it from [sph]).
struct Inlet {
  Vec3d center{};                 // m, inside the box
  Vec3d direction{0, 0, -1};      // any length > 0: the flow's direction
  double radius = 0;              // m, > 0
  double speed = 0;               // m/s, > 0
  double spacing = 0;             // m, > 0
  double start = 0;               // s, ≥ 0
  std::optional<double> stop;     // s, > start; none: emits to the end of the run
  double mass = 0;                // kg per particle (resolved)
};

// An outlet ([[outlets]]): a box from which fluid particles are removed after
// every step (boundary particles stay). It may reach outside the scene's box.
struct Outlet {
  Box<double> region;             // m: min < max on every axis
};

// The obstacle shapes' names, which are also their [[particles]] kinds.
inline constexpr std::array<EnumName<ObstacleSource::Shape>, 5> kObstacleShapeNames{{
    {"obstacle_box", ObstacleSource::Shape::Box},
    {"obstacle_sphere", ObstacleSource::Shape::Sphere},
    {"obstacle_cylinder", ObstacleSource::Shape::Cylinder},
    {"obstacle_plane", ObstacleSource::Shape::Plane},
    {"obstacle_mesh", ObstacleSource::Shape::Mesh},
}};

using ParticleSource =
    std::variant<LatticeSource, RandomSource, ListSource, StellarSource, SnapshotSource, ObstacleSource, FluidFillSource>;

// box.walls: the thesis's clamp (the box's two passes), or the box's faces
// sampled by boundary particles just outside it (scene::wall_offset(): where
// a fluid block filling the box starts at the rest density; the clamp then
// stays, one spacing further out, as a safety net that a fluid particle meets
// only if it leaked through).
enum class Walls { Clamp, Particles };
inline constexpr std::array<EnumName<Walls>, 2> kWallsNames{{{"clamp", Walls::Clamp}, {"particles", Walls::Particles}}};

struct Scene {
  std::string file;                        // where it came from, for messages
  std::string toml;                        // the scene as TOML after --set overrides (parse_scene fills
                                           // it): saved beside a run's outputs so it can be resumed
  std::uint32_t format_version = kSceneFormatVersion;  // root key `format`, 1 ≤ version ≤ kSceneFormatVersion
  Units units = Units::SI;                 // simulation.units; a loaded scene defaults to NBody when it has
                                           // [nbody] and no [sph], else SI
  double gravitational_constant = kGravitationalConstantSI;  // G, resolved: nbody.G if given, else 1 in
                                           // N-body units and kGravitationalConstantSI in SI (> 0)
  Precision precision = Precision::Float;  // simulation.precision, default "float"
  double dt = 0;                           // simulation.dt, s, > 0 (adaptive: the largest step, dt_max)
  std::optional<double> end_time;          // simulation.end_time, s (exactly one of end_time, steps)
  std::optional<std::uint64_t> steps;      // simulation.steps
  std::size_t block_size = 1024;           // simulation.block_size: particles per work block, ≥ 1
  double rebalance_threshold = 1.05;       // simulation.rebalance_threshold: on MPI ranks, new cuts when the
                                           // largest rank's cost over the mean passes it (≥ 1; dist/rank_order.hpp)

  // Time-step control (docs/stability.md). dt = "adaptive" chooses every step
  // from the conditions below (each solver's add_limits(), force/solver.hpp); a fixed dt is checked
  // against them after every step (the blow-up guard).
  bool adaptive_dt = false;                // simulation.dt = "adaptive"
  double dt_min = 0;                       // simulation.dt_min, s: adaptive floor; 0 = 1e-6 × the first step
  double cfl = 0.6;                        // simulation.cfl: C_cfl, SPH Δt ≤ C_cfl·h/(c + |v|max)
  double force_factor = 0.4;               // simulation.force_factor: C_force, SPH Δt ≤ C_force·sqrt(h/|a|max)
  double viscous_factor = 0.125;           // simulation.viscous_factor: C_visc, SPH Δt ≤ C_visc·h²·ρ/μ
  double eta = 0.75;                       // simulation.eta: η, gravity Δt ≤ η·sqrt(ε/|a|max)
  // simulation.time_steps = "block": dt is the largest step, each particle
  // steps in its own bin dt/2^k, k ≤ simulation.max_bin, by η·sqrt(ε/|a_i|).
  TimeSteps time_steps = TimeSteps::Global;
  std::uint32_t max_bin = 20;              // simulation.max_bin, in [0, 40]
  // simulation.max_energy_error: a run whose forces and walls all conserve energy
  // stops (a blow-up) when |E − E0|/|E0| at an output time exceeds this; 0 = never.
  double max_energy_error = 0.1;

  bool walls = true;                       // a [box] section: walls; without one, open space
  Box<double> box;                         // box.min, box.max, m (used only with walls)
  double restitution = 0.5;                // box.restitution, e in [0, 1]
  Walls wall_kind = Walls::Clamp;          // box.walls
  double wall_spacing = 0;                 // m: the boundary particles' spacing on the walls (with
                                           // box.walls = "particles": the first fluid_block's spacing)

  Vec3d gravity{0, 0, -9.81};              // forces.gravity, m/s², uniform
  double damping = 0;                      // forces.damping, 1/s, ≥ 0: a drag a = −damping·v (settling runs)

  double output_interval = 0;              // output.interval, s of simulated time; 0 = first and last frame only
  std::vector<OutputFormat> formats{OutputFormat::Vtp};  // output.format: "vtp", "csv" and/or "hdf5"
  // The fluid's surface per frame (SPH scenes only): output.surface, and the
  // reconstruction's kernel radius, grid cell (both in particle spacings,
  // (m/ρ0)^(1/3)) and iso level (docs/surface.md).
  SurfaceFormat surface = SurfaceFormat::None;
  double surface_radius = 2.0;             // output.surface_radius, spacings
  double surface_cell = 0.5;               // output.surface_cell, spacings
  double surface_iso = 0.5;                // output.surface_iso, in (0, 1)
  // probes.csv (docs/sph.md, Probes): the probes' interval (0: output.interval)
  // and whether it records the force and torque the fluid exerts on every
  // obstacle and on walls of particles.
  double probes_interval = 0;              // output.probes_interval, s of simulated time
  bool obstacle_forces = false;            // output.obstacle_forces
  std::vector<Probe> probes;               // [[probes]]
  std::vector<Inlet> inlets;               // [[inlets]]
  std::vector<Outlet> outlets;             // [[outlets]]

  std::vector<ParticleSource> sources;     // [[particles]]; a "fluid_block" becomes a LatticeSource
                                           // whose mass gives the rest density (sph::lattice_mass_for_density)

  // [sph]: present for fluid scenes. smoothing_length is resolved (given, or
  // from sph.neighbours and the first fluid block's spacing).
  std::optional<sph::SphParameters> sph;

  // [random_box]: the thesis's benchmark set-up (section 5), when present: N =
  // `particles` random particles in the box [0, L]³ with L³ = N·(4/3)π h³ / k,
  // each of mass ρ0·L³/N; the box and a RandomSource are derived from it.
  struct RandomBox {
    std::uint64_t particles = 0;   // N (root key `particles`)
    double neighbours = 25;         // k (random_box.neighbours)
    std::uint64_t seed = 1;        // random_box.seed
  };
  std::optional<RandomBox> random_box;

  // [nbody]: self-gravity (Barnes–Hut or direct sum), with G = gravitational_constant.
  std::optional<gravity::GravitySettings> nbody;

  // Number of steps the scene asks for: `steps`, or ceil(end_time / dt) (a step
  // that would overshoot end_time by less than 1e-9·dt is not added). With
  // adaptive steps and an end_time, the fewest steps (all of dt_max).
  std::uint64_t total_steps() const;

  // True when the run writes probes.csv: probes, or the obstacles' forces.
  bool has_probe_output() const { return !probes.empty() || obstacle_forces; }

  // True when the particle count changes during a run (inlets or outlets).
  bool has_inlets_or_outlets() const { return !inlets.empty() || !outlets.empty(); }

  // True when an obstacle has a `motion`.
  bool has_moving_obstacles() const {
    for (const auto& s : sources)
      if (const auto* o = std::get_if<ObstacleSource>(&s); o && o->motion) return true;
    return false;
  }

  // True when the scene has boundary particles (box.walls = "particles" or an obstacle source).
  bool has_boundary_particles() const {
    if (walls && wall_kind == Walls::Particles) return true;
    for (const auto& s : sources)
      if (std::holds_alternative<ObstacleSource>(s)) return true;
    return false;
  }
};

// A scene file that cannot be used. what() names the file, the key (or line
// and column for syntax errors) and the reason, in one line.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace swirl::scene
