// Turning a scene's particle sources into particles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/scene/scene.hpp"

namespace swirl::scene {

// Number of particles the sources will make (without making them).
std::size_t count_particles(const Scene& scene);

// Makes the particles of every source, in source order, with ids 0..N-1 in that
// order, positions, velocities and masses set and every other field zero.
// Deterministic: the same scene gives the same particles on any machine.
// A scene with boundary particles (Scene::has_boundary_particles()) also
// gets the integer field "kind" (core/particle_kind.hpp): 0 for fluid, 1 for
// the obstacles' particles and then, after every source, the walls'
// (box.walls = "particles"). A boundary particle starts at rest with the mass
// ρ0·spacing³ (a placeholder: the SPH solver replaces it by its volume weight ψ).
template <class Real>
ParticleSet<Real> make_particles(const Scene& scene);

// The boundary particles' positions of one obstacle (the sampling rules at
// ObstacleSource), in a fixed order.
std::vector<Vec3d> obstacle_points(const ObstacleSource& obstacle);

// How far outside the box's faces the walls' boundary particles lie
// (box.walls = "particles"; 0 otherwise): d − s/2, d from
// sph::wall_distance_for_density() for the scene's kernel, h and the walls'
// spacing s, so that a fluid_block's first layer (s/2 inside the box) starts
// at the rest density (0.59 s for the cubic spline at h = 1.95 s).
double wall_offset(const Scene& scene);

// The walls' boundary particles (box.walls = "particles"): the surface of the
// box grown by wall_offset() on every side, sampled as an obstacle_box at
// scene.wall_spacing; empty for other scenes.
std::vector<Vec3d> wall_points(const Scene& scene);

// The particles of one obstacle by their ids: make_particles() numbers the
// particles 0..N−1 in source order, the walls' last, and an id travels with
// its particle through every reorder and checkpoint, so the ids
// [first, first + count) are the obstacle's for the whole run (checkpoints
// need no field of their own for it). `centre` is the point torques are taken
// about (obstacle_centre(); the box's centre for the walls).
struct ObstacleIds {
  std::string name;  // its `name`, or "obstacle<k>" (k from 1, in source order); "walls" for the walls
  std::uint64_t first = 0;
  std::uint64_t count = 0;
  Vec3d centre{};    // at rest: a moving obstacle's is carried by its motion
  std::optional<boundary::RigidMotion> motion;  // its `motion`, if it moves

  // The centre at time t (m).
  Vec3d centre_at(double t) const { return motion ? motion->pose(t).position(centre) : centre; }
};

// Every obstacle in source order, then the walls (box.walls = "particles").
std::vector<ObstacleIds> obstacle_ids(const Scene& scene);

extern template ParticleSet<float> make_particles<float>(const Scene&);
extern template ParticleSet<double> make_particles<double>(const Scene&);

}  // namespace swirl::scene
