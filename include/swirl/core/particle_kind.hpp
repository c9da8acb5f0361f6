// Particle kinds: the integer field "kind" that tells a fluid particle from a
// boundary particle (Akinci et al. 2012: static walls and obstacles sampled by
// particles that enter the fluid's density and pressure but do not move).
//
// A scene with boundary particles (box.walls = "particles", or an obstacle_*
// source) gives its particle set this field (scene/initial_conditions.hpp);
// a set without it is all fluid. Frames put boundary particles in their own
// series, boundary_NNNNNN.* (io/frame_names.hpp), both with an Int32 array
// "kind"; the field travels with checkpoints and reorders like every integer field.
//
// What "boundary" means to the pipeline:
//  - the simulation zeroes a boundary particle's acceleration after every
//    force evaluation (sim/simulation.hpp), so that with v = 0 every stepper's
//    update leaves it exactly where it is (x += 0·Δt + ½·0·Δt²); a moving
//    obstacle's particles are put at their prescribed x and v before every
//    evaluation instead (boundary/moving_boundaries.hpp);
//  - the SPH solver (sph/sph_fluid.hpp) stores its volume weight ψ_b in its
//    mass and leaves it out of the fluid's diagnostics and solves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>
#include <string_view>

namespace swirl {

// The integer field's name.
inline constexpr std::string_view kKindField = "kind";

// Its values.
enum class ParticleKind : std::int32_t { Fluid = 0, Boundary = 1 };

// True when a particle of kind value k is a (static) boundary particle.
constexpr bool is_boundary(std::int32_t k) { return k != static_cast<std::int32_t>(ParticleKind::Fluid); }

// The storage indices of a set's boundary particles and of the rest (fluid, or
// stars), each in storage order: the two frame series. Both are empty for a
// set without the kind field (then all of it is "the rest"). `Set` is a
// ParticleSet<Real> (find_int_field, int_field, npos).
struct KindSplit {
  std::vector<std::size_t> rest, boundary;
};
template <class Set>
KindSplit split_by_kind(const Set& p) {
  KindSplit out;
  const std::size_t field = p.find_int_field(kKindField);
  if (field == Set::npos) return out;
  const auto& kind = p.int_field(field);
  for (std::size_t i = 0; i < p.size(); ++i) (is_boundary(kind[i]) ? out.boundary : out.rest).push_back(i);
  return out;
}

}  // namespace swirl
