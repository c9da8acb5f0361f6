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

#include <cstdint>
#include <string_view>

namespace swirl {

// The integer field's name.
inline constexpr std::string_view kKindField = "kind";

// Its values.
enum class ParticleKind : std::int32_t { Fluid = 0, Boundary = 1 };

// True when a particle of kind value k is a (static) boundary particle.
constexpr bool is_boundary(std::int32_t k) { return k != static_cast<std::int32_t>(ParticleKind::Fluid); }

}  // namespace swirl
