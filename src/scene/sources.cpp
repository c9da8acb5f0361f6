#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <variant>

#include <fmt/format.h>

#include "sources.hpp"
#include "swirl/core/particle_kind.hpp"
#include "swirl/core/random.hpp"
#include "swirl/scene/fluid_fill.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/mesh_sampling.hpp"
#include "swirl/sph/lattice_mass.hpp"

namespace swirl::scene {
namespace detail {

std::array<std::uint64_t, 3> lattice_counts(const LatticeSource& source) {
  std::array<std::uint64_t, 3> n{};
  const Vec3d extent = source.region.extent();
  for (int axis = 0; axis < 3; ++axis) {
    const double r = extent[axis] / source.spacing;
    // Beyond 2^53 the count is far over the particle limit anyway, and the
    // conversion below would no longer be exact (or defined, for inf and NaN).
    if (std::isnan(r) || r >= 0x1p53) {
      n[axis] = kSaturated;
    } else if (r > 0) {
      // The tolerance absorbs rounding in extent / spacing (0.3 / 0.1 = 2.9999999999999996).
      n[axis] = static_cast<std::uint64_t>(std::floor(r + r * 1e-12));
    }
  }
  return n;
}

std::uint64_t source_count(const ParticleSource& source) {
  struct {
    std::uint64_t operator()(const LatticeSource& s) const {
      const auto n = lattice_counts(s);
      return mul_sat(mul_sat(n[0], n[1]), n[2]);
    }
    std::uint64_t operator()(const RandomSource& s) const { return s.count; }
    std::uint64_t operator()(const ListSource& s) const { return s.positions.size(); }
    std::uint64_t operator()(const StellarSource& s) const { return s.count; }
    std::uint64_t operator()(const SnapshotSource& s) const { return s.content ? s.content->positions.size() : 0; }
    std::uint64_t operator()(const ObstacleSource& s) const { return obstacle_count(s); }
    std::uint64_t operator()(const FluidFillSource& s) const {
      // Beyond the limits the bound stands for the count (validation refuses it either way).
      const std::uint64_t bound = fill_lattice_bound(s);
      if (bound > kMaxParticles) return bound;
      if (s.shape == FluidFillSource::Shape::Mesh && (!s.mesh || mul_sat(bound, s.mesh->triangles.size()) > kMaxFillWork))
        return 0;
      return fill_points(s).size();
    }
  } count;
  return std::visit(count, source);
}

namespace {

// Intervals of length ≈ spacing along an extent: round(extent/spacing), at
// least 1 for a positive extent, 0 for none; kSaturated when not finite or huge.
std::uint64_t intervals(double extent, double spacing) {
  const double r = extent / spacing;
  if (!(r < 0x1p40)) return kSaturated;
  if (!(extent > 0)) return 0;
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(r)));
}

std::uint64_t box_surface_count(const Box<double>& b, double spacing) {
  std::uint64_t all = 1, inner = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const std::uint64_t n = intervals(b.hi[axis] - b.lo[axis], spacing);
    if (n == kSaturated) return kSaturated;
    all = mul_sat(all, n + 1);
    inner = mul_sat(inner, n > 0 ? n - 1 : 0);
  }
  return all == kSaturated ? kSaturated : all - inner;
}

// Points on a ring of radius r: round(2πr/spacing), at least 3 (1 at r = 0).
std::uint64_t ring_count(double r, double spacing) {
  if (!(r > 0)) return 1;
  const std::uint64_t n = intervals(2 * std::numbers::pi * r, spacing);
  return n == kSaturated ? n : std::max<std::uint64_t>(3, n);
}

// The rings of an end disc of a cylinder inside its rim: radii r·j/n_r, j < n_r.
std::uint64_t disc_count(double r, double spacing) {
  const std::uint64_t rings = intervals(r, spacing);
  if (rings == kSaturated || rings > (std::uint64_t{1} << 24)) return kSaturated;
  std::uint64_t total = 0;
  for (std::uint64_t j = 0; j < rings; ++j)
    total = add_sat(total, ring_count(r * static_cast<double>(j) / static_cast<double>(rings), spacing));
  return total;
}

}  // namespace

std::uint64_t obstacle_count(const ObstacleSource& s) {
  using Shape = ObstacleSource::Shape;
  if (!(s.spacing > 0)) return 0;  // validation names the spacing
  switch (s.shape) {
    case Shape::Box: return box_surface_count(s.region, s.spacing);
    case Shape::Sphere: {
      const double n = std::round(4 * std::numbers::pi * s.radius * s.radius / (s.spacing * s.spacing));
      if (!(n < 0x1p40)) return kSaturated;
      return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(n));
    }
    case Shape::Cylinder: {
      const Vec3d axis = s.end - s.start;
      const std::uint64_t rings = intervals(norm(axis), s.spacing);
      if (rings == kSaturated) return kSaturated;
      const std::uint64_t side = mul_sat(rings + 1, ring_count(s.radius, s.spacing));
      return add_sat(side, mul_sat(2, disc_count(s.radius, s.spacing)));
    }
    case Shape::Plane: {
      // Bounded first: the lattice tried is (2R + 1)² points.
      const double reach = std::ceil(norm(s.clip.hi - s.clip.lo) / s.spacing);
      if (!(reach < 0x1p15)) return kSaturated;
      return obstacle_points(s).size();
    }
    case Shape::Mesh: return mesh_point_count(s);
  }
  return 0;
}

std::uint64_t wall_count(const Scene& scene) {
  if (!scene.walls || scene.wall_kind != Walls::Particles || !(scene.wall_spacing > 0)) return 0;
  return box_surface_count(grown_box(scene), scene.wall_spacing);
}

Box<double> grown_box(const Scene& scene) {
  const double out = wall_offset(scene);
  return {scene.box.lo - Vec3d{out, out, out}, scene.box.hi + Vec3d{out, out, out}};
}

}  // namespace detail

namespace {

// a + b·c rounded twice. Separate statements, because a compiler may fuse one
// expression into a multiply-add (Clang does by default), which rounds once and
// would move particles by an ulp on some machines only.
double mul_add(double a, double b, double c) {
  const double bc = b * c;
  return a + bc;
}

// Rounding in lo + u·extent can land an ulp past the region; the region must hold.
Vec3d clamp_to(const Box<double>& region, Vec3d p) {
  for (int axis = 0; axis < 3; ++axis) p[axis] = std::clamp(p[axis], region.lo[axis], region.hi[axis]);
  return p;
}

// The lattice points of [b.lo, b.hi] that lie on its surface, n_a =
// intervals(extent_a) per axis (0: the one plane lo_a), x fastest.
std::vector<Vec3d> box_surface(const Box<double>& b, double spacing) {
  std::array<std::uint64_t, 3> n{};
  for (int axis = 0; axis < 3; ++axis) n[static_cast<std::size_t>(axis)] = detail::intervals(b.hi[axis] - b.lo[axis], spacing);
  const auto coordinate = [&](int axis, std::uint64_t k) {
    const std::uint64_t count = n[static_cast<std::size_t>(axis)];
    if (count == 0 || k == 0) return b.lo[axis];
    if (k == count) return b.hi[axis];
    return mul_add(b.lo[axis], (b.hi[axis] - b.lo[axis]) / static_cast<double>(count), static_cast<double>(k));
  };
  std::vector<Vec3d> out;
  for (std::uint64_t k = 0; k <= n[2]; ++k)
    for (std::uint64_t j = 0; j <= n[1]; ++j) {
      const bool edge = k == 0 || k == n[2] || j == 0 || j == n[1];
      for (std::uint64_t i = 0; i <= n[0]; ++i) {
        if (!edge && i != 0 && i != n[0]) continue;  // inside the box
        out.push_back({coordinate(0, i), coordinate(1, j), coordinate(2, k)});
      }
    }
  return out;
}

// count points on the circle of radius r around c in the plane (u, v), from angle θ0.
void ring(std::vector<Vec3d>& out, const Vec3d& c, const Vec3d& u, const Vec3d& v, double r, std::uint64_t count,
          double theta0) {
  if (!(r > 0)) {
    out.push_back(c);
    return;
  }
  for (std::uint64_t k = 0; k < count; ++k) {
    const double theta = theta0 + 2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(count);
    out.push_back(c + u * (r * std::cos(theta)) + v * (r * std::sin(theta)));
  }
}

template <class Real>
class Filler {
 public:
  Filler(ParticleSet<Real>& out, const Scene& scene) : out_(out), scene_(scene) {
    if (const std::size_t k = out.find_int_field(kKindField); k != ParticleSet<Real>::npos) kind_ = out.int_field(k).data();
  }

  void put(const Vec3d& x, const Vec3d& v, double m, ParticleKind kind = ParticleKind::Fluid) {
    out_.position.set(next_, x.cast<Real>());
    out_.velocity.set(next_, v.cast<Real>());
    out_.mass[next_] = static_cast<Real>(m);
    out_.id[next_] = next_;
    if (kind_) kind_[next_] = static_cast<std::int32_t>(kind);
    ++next_;
  }

  // Boundary particles at rest with the placeholder mass ρ0·spacing³ (the SPH solver sets ψ).
  void put_boundary(const std::vector<Vec3d>& points, double spacing) {
    const double rho0 = scene_.sph ? scene_.sph->rest_density : 1.0;
    for (const auto& x : points) put(x, Vec3d{}, rho0 * spacing * spacing * spacing, ParticleKind::Boundary);
  }

  void operator()(const ObstacleSource& s) { put_boundary(obstacle_points(s), s.spacing); }

  void operator()(const FluidFillSource& s) {
    for (const Vec3d& x : fill_points(s)) put(x, s.velocity, s.mass);
  }

  void operator()(const LatticeSource& s) {
    const auto n = detail::lattice_counts(s);
    const double amplitude = s.jitter * s.spacing;
    SplitMix64 rng(s.seed);
    for (std::uint64_t k = 0; k < n[2]; ++k) {
      for (std::uint64_t j = 0; j < n[1]; ++j) {
        for (std::uint64_t i = 0; i < n[0]; ++i) {
          const std::uint64_t index[3] = {i, j, k};
          Vec3d p;
          for (int axis = 0; axis < 3; ++axis)
            p[axis] = mul_add(s.region.lo[axis], s.spacing, static_cast<double>(index[axis]) + 0.5);
          if (amplitude > 0)
            for (int axis = 0; axis < 3; ++axis) p[axis] = mul_add(p[axis], amplitude, 2 * rng.uniform() - 1);
          put(clamp_to(s.region, p), s.velocity, s.mass);
        }
      }
    }
  }

  void operator()(const RandomSource& s) {
    SplitMix64 rng(s.seed);
    const Vec3d extent = s.region.extent();
    for (std::size_t n = 0; n < s.count; ++n) {
      Vec3d p;
      for (int axis = 0; axis < 3; ++axis) p[axis] = mul_add(s.region.lo[axis], rng.uniform(), extent[axis]);
      put(clamp_to(s.region, p), s.velocity, s.mass);
    }
  }

  void operator()(const ListSource& s) {
    for (std::size_t n = 0; n < s.positions.size(); ++n)
      put(s.positions[n], s.velocities.empty() ? Vec3d{} : s.velocities[n], s.masses[n]);
  }

  void operator()(const StellarSource& s) {
    using Model = StellarSource::Model;
    ParticleSet<Real> model;
    switch (s.model) {
      case Model::Plummer: model = gravity::plummer<Real>(s.count, s.seed, s.plummer); break;
      case Model::UniformSphere: model = gravity::uniform_sphere<Real>(s.count, s.seed, s.size, s.mass); break;
      case Model::UniformCube: model = gravity::uniform_cube<Real>(s.count, s.seed, s.size, s.mass); break;
      case Model::ColdCollapse: model = gravity::cold_collapse<Real>(s.count, s.seed); break;
      case Model::PlummerCollision: model = gravity::plummer_collision<Real>(s.count, s.seed, s.collision); break;
      case Model::Hernquist: model = gravity::hernquist<Real>(s.count, s.seed, s.hernquist); break;
      case Model::Nfw: model = gravity::nfw<Real>(s.count, s.seed, s.nfw); break;
      case Model::King: model = gravity::king<Real>(s.count, s.seed, s.king); break;
      case Model::DiskGalaxy: model = gravity::disk_galaxy<Real>(s.count, s.seed, s.disk); break;
    }
    for (std::size_t n = 0; n < model.size(); ++n)
      put(model.position.get(n).template cast<double>() + s.offset,
          model.velocity.get(n).template cast<double>() + s.velocity, double(model.mass[n]));
  }

  void operator()(const SnapshotSource& s) {
    const SnapshotContent& c = *s.content;  // check_buildable() refused a source without it
    for (std::size_t n = 0; n < c.positions.size(); ++n)
      put(detail::moved(c.positions[n], s.offset), detail::moved(c.velocities[n], s.velocity), c.masses[n]);
  }

  std::size_t count() const { return next_; }

 private:
  ParticleSet<Real>& out_;
  const Scene& scene_;
  std::int32_t* kind_ = nullptr;
  std::size_t next_ = 0;
};

// Values finite in double can overflow the scene's precision (1e300 in float),
// a mass underflow to 0, and a generator overflow on extreme sizes: refused
// here, naming the source, instead of handing a solver inf or NaN.
template <class Real>
void check_finite(const Scene& scene, std::size_t source, const ParticleSet<Real>& p, std::size_t begin,
                  std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) {
    const Vec3<Real> x = p.position.get(i), v = p.velocity.get(i);
    const Real m = p.mass[i];
    if (std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z) && std::isfinite(v.x) && std::isfinite(v.y) &&
        std::isfinite(v.z) && std::isfinite(m) && m > 0)
      continue;
    throw SceneError(fmt::format("{}: particles[{}]: particle {} does not fit {} precision: position ({}, {}, {}), "
                                 "velocity ({}, {}, {}), mass {}",
                                 scene.file, source, i, sizeof(Real) == 4 ? "float" : "double", x.x, x.y, x.z, v.x,
                                 v.y, v.z, m));
  }
}

// A Scene built in code has not been through validation; these would otherwise
// read out of bounds or allocate without limit.
void check_buildable(const Scene& scene, std::uint64_t count) {
  if (count > detail::kMaxParticles)
    throw SceneError(fmt::format("{}: particles: {} particles, more than the limit of {} (2^31)", scene.file,
                                 count == detail::kSaturated ? std::string("over 1.8e19") : std::to_string(count),
                                 detail::kMaxParticles));
  for (std::size_t k = 0; k < scene.sources.size(); ++k) {
    const auto* list = std::get_if<ListSource>(&scene.sources[k]);
    if (list && (list->masses.size() != list->positions.size() ||
                 (!list->velocities.empty() && list->velocities.size() != list->positions.size())))
      throw SceneError(fmt::format("{}: particles[{}]: masses and velocities must have one entry per position",
                                   scene.file, k));
    const auto* mesh = std::get_if<ObstacleSource>(&scene.sources[k]);
    if (mesh && mesh->shape == ObstacleSource::Shape::Mesh && (!mesh->mesh || !mesh_indices_valid(*mesh->mesh)))
      throw SceneError(fmt::format("{}: particles[{}].file: {} has not been read, or its triangles name vertices it "
                                   "does not have (load_scene reads it)",
                                   scene.file, k, mesh->file));
    const auto* fill = std::get_if<FluidFillSource>(&scene.sources[k]);
    if (fill && fill->shape == FluidFillSource::Shape::Mesh && (!fill->mesh || !mesh_indices_valid(*fill->mesh)))
      throw SceneError(fmt::format("{}: particles[{}].file: {} has not been read, or its triangles name vertices it "
                                   "does not have (load_scene reads it)",
                                   scene.file, k, fill->file));
    const auto* snapshot = std::get_if<SnapshotSource>(&scene.sources[k]);
    if (snapshot && (!snapshot->content || snapshot->content->velocities.size() != snapshot->content->positions.size() ||
                     snapshot->content->masses.size() != snapshot->content->positions.size()))
      throw SceneError(fmt::format("{}: particles[{}].file: {} has not been read (load_scene reads it)", scene.file, k,
                                   snapshot->file));
  }
}

std::uint64_t total_count(const Scene& scene) {
  std::uint64_t total = detail::wall_count(scene);
  for (const auto& source : scene.sources) total = detail::add_sat(total, detail::source_count(source));
  return total;
}

}  // namespace

std::size_t count_particles(const Scene& scene) {
  const std::uint64_t total = total_count(scene);
  return total > std::numeric_limits<std::size_t>::max() ? std::numeric_limits<std::size_t>::max()
                                                         : static_cast<std::size_t>(total);
}

std::vector<ObstacleIds> obstacle_ids(const Scene& scene) {
  std::vector<ObstacleIds> out;
  std::uint64_t first = 0;
  std::size_t k = 0;
  for (const auto& source : scene.sources) {
    const std::uint64_t n = detail::source_count(source);
    if (const auto* o = std::get_if<ObstacleSource>(&source)) {
      ++k;
      out.push_back({o->name.empty() ? fmt::format("obstacle{}", k) : o->name, first, n, obstacle_centre(*o), o->motion});
    }
    first = detail::add_sat(first, n);
  }
  if (scene.walls && scene.wall_kind == Walls::Particles)
    out.push_back({"walls", first, detail::wall_count(scene), (scene.box.lo + scene.box.hi) * 0.5, std::nullopt});
  return out;
}

template <class Real>
ParticleSet<Real> make_particles(const Scene& scene) {
  const std::uint64_t count = total_count(scene);
  check_buildable(scene, count);
  ParticleSet<Real> particles(static_cast<std::size_t>(count));
  if (scene.has_boundary_particles()) particles.add_int_field(std::string(kKindField));
  Filler<Real> fill(particles, scene);
  for (std::size_t k = 0; k < scene.sources.size(); ++k) {
    const std::size_t begin = fill.count();
    try {
      std::visit(fill, scene.sources[k]);
    } catch (const std::invalid_argument& e) {
      // A model generator's precondition (gravity/initial_conditions.hpp) that validation missed.
      throw SceneError(fmt::format("{}: particles[{}]: {}", scene.file, k, e.what()));
    }
    check_finite(scene, k, particles, begin, fill.count());
  }
  fill.put_boundary(wall_points(scene), scene.wall_spacing);
  return particles;
}

std::vector<Vec3d> obstacle_points(const ObstacleSource& s) {
  using Shape = ObstacleSource::Shape;
  const double spacing = s.spacing;
  std::vector<Vec3d> out;
  if (!(spacing > 0)) return out;
  if (s.shape == Shape::Mesh) return mesh_points(s);  // bounded by kMaxMeshParticles
  if (s.shape != Shape::Plane && detail::obstacle_count(s) > detail::kMaxParticles) return out;
  switch (s.shape) {
    case Shape::Box: return box_surface(s.region, spacing);
    case Shape::Sphere: {
      // A Fibonacci lattice: N points of equal area, z evenly spaced, longitude by the golden angle.
      const std::uint64_t n = detail::obstacle_count(s);
      const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
      for (std::uint64_t k = 0; k < n; ++k) {
        const double z = 1 - (2 * static_cast<double>(k) + 1) / static_cast<double>(n);
        const double rho = std::sqrt(std::max(0.0, 1 - z * z)), phi = golden * static_cast<double>(k);
        out.push_back(s.center + Vec3d{rho * std::cos(phi), rho * std::sin(phi), z} * s.radius);
      }
      return out;
    }
    case Shape::Cylinder: {
      const Vec3d axis = s.end - s.start;
      const double length = norm(axis);
      const Vec3d e = axis * (1 / length);
      const auto [u, v] = basis_around(e);
      const std::uint64_t rings = detail::intervals(length, spacing), around = detail::ring_count(s.radius, spacing);
      const double half_step = std::numbers::pi / static_cast<double>(around);
      for (std::uint64_t k = 0; k <= rings; ++k)  // the side, every other ring turned by half a step
        ring(out, s.start + axis * (static_cast<double>(k) / static_cast<double>(rings)), u, v, s.radius, around,
             k % 2 ? half_step : 0.0);
      const std::uint64_t discs = detail::intervals(s.radius, spacing);
      for (const Vec3d& c : {s.start, s.end})  // the end discs inside their rims
        for (std::uint64_t j = 0; j < discs; ++j) {
          const double r = s.radius * static_cast<double>(j) / static_cast<double>(discs);
          ring(out, c, u, v, r, detail::ring_count(r, spacing), 0.0);
        }
      return out;
    }
    case Shape::Plane: {
      const Vec3d n = s.normal * (1 / norm(s.normal));
      const auto [u, v] = basis_around(n);
      const double steps = std::ceil(norm(s.clip.hi - s.clip.lo) / spacing);
      if (!(steps < 0x1p15) || !(norm(s.normal) > 0)) return out;  // obstacle_count() saturates; validation refuses
      const auto reach = static_cast<std::int64_t>(steps);
      for (std::int64_t b = -reach; b <= reach; ++b)
        for (std::int64_t a = -reach; a <= reach; ++a) {
          const Vec3d p = s.point + u * (spacing * static_cast<double>(a)) + v * (spacing * static_cast<double>(b));
          if (s.clip.contains(p)) out.push_back(p);
        }
      return out;
    }
    case Shape::Mesh: break;  // above
  }
  return out;
}

double wall_offset(const Scene& scene) {
  if (!scene.walls || scene.wall_kind != Walls::Particles || !scene.sph || !(scene.wall_spacing > 0)) return 0;
  const auto& f = *scene.sph;
  const double d = sph::wall_distance_for_density(scene.wall_spacing, f.smoothing_length,
                                                  f.method == sph::SphMethod::Dfsph ? f.kernel : sph::SphKernel::Thesis);
  return d - 0.5 * scene.wall_spacing;  // a fluid block's first layer is half a spacing inside the box
}

std::vector<Vec3d> wall_points(const Scene& scene) {
  if (detail::wall_count(scene) == 0) return {};
  return box_surface(detail::grown_box(scene), scene.wall_spacing);
}

template ParticleSet<float> make_particles<float>(const Scene&);
template ParticleSet<double> make_particles<double>(const Scene&);

}  // namespace swirl::scene
