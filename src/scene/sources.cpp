#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <variant>

#include <fmt/format.h>

#include "sources.hpp"
#include "swirl/core/random.hpp"
#include "swirl/scene/initial_conditions.hpp"

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
  } count;
  return std::visit(count, source);
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

template <class Real>
class Filler {
 public:
  explicit Filler(ParticleSet<Real>& out) : out_(out) {}

  void put(const Vec3d& x, const Vec3d& v, double m) {
    out_.position.set(next_, x.cast<Real>());
    out_.velocity.set(next_, v.cast<Real>());
    out_.mass[next_] = static_cast<Real>(m);
    out_.id[next_] = next_;
    ++next_;
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
    const auto* snapshot = std::get_if<SnapshotSource>(&scene.sources[k]);
    if (snapshot && (!snapshot->content || snapshot->content->velocities.size() != snapshot->content->positions.size() ||
                     snapshot->content->masses.size() != snapshot->content->positions.size()))
      throw SceneError(fmt::format("{}: particles[{}].file: {} has not been read (load_scene reads it)", scene.file, k,
                                   snapshot->file));
  }
}

std::uint64_t total_count(const Scene& scene) {
  std::uint64_t total = 0;
  for (const auto& source : scene.sources) total = detail::add_sat(total, detail::source_count(source));
  return total;
}

}  // namespace

std::size_t count_particles(const Scene& scene) {
  const std::uint64_t total = total_count(scene);
  return total > std::numeric_limits<std::size_t>::max() ? std::numeric_limits<std::size_t>::max()
                                                         : static_cast<std::size_t>(total);
}

template <class Real>
ParticleSet<Real> make_particles(const Scene& scene) {
  const std::uint64_t count = total_count(scene);
  check_buildable(scene, count);
  ParticleSet<Real> particles(static_cast<std::size_t>(count));
  Filler<Real> fill(particles);
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
  return particles;
}

template ParticleSet<float> make_particles<float>(const Scene&);
template ParticleSet<double> make_particles<double>(const Scene&);

}  // namespace swirl::scene
