// Building the Simulation a scene describes: its particles, its stepper (with
// the box's walls, or open space; block time steps with simulation.time_steps;
// DFSPH's stepper with sph.method = "dfsph")
// and its solvers, each made from its own
// section of the scene — SPH from [sph], self-gravity from [nbody] (G from
// simulation.units / nbody.G), a uniform field from forces.gravity, a drag
// from forces.damping. Nothing above this file knows which solvers a run has:
// the run loop, the CLI and the tools see Solver<Real> only (a tool that
// wants one kind's own figures asks Simulation::find_solver<T>()).
#pragma once

#include <memory>
#include <variant>
#include <vector>

#include "swirl/boundary/moving_boundaries.hpp"

#include "swirl/force/damping.hpp"
#include "swirl/force/uniform_gravity.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/integrate/block_steps.hpp"
#include "swirl/integrate/kick_drift.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/dfsph_stepper.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace swirl::sim {

// The scene's simulation with these particles (its own: scene::make_particles;
// none on the MPI ranks other than 0, which receive their share at start).
template <class Real>
Simulation<Real> build_simulation(const scene::Scene& scene, ParticleSet<Real> particles) {
  SimulationSettings settings;
  settings.dt = scene.dt;
  settings.block_size = scene.block_size;
  settings.rebalance_threshold = scene.rebalance_threshold;
  settings.adaptive = scene.adaptive_dt;
  settings.dt_min = scene.dt_min;
  // A particle further outside than the kernel support has left the box (the guard).
  if (scene.walls && scene.sph) settings.escape_length = scene.sph->smoothing_length;
  std::optional<boundary::BoxCollision<Real>> box;
  if (scene.walls) {
    // With box.walls = "particles" the walls are boundary particles just
    // outside the box (scene::wall_offset()); the clamp stays one spacing
    // further out, a safety net that only a particle which leaked through meets.
    Box<double> clamp = scene.box;
    if (scene.wall_kind == scene::Walls::Particles) {
      const double reach = scene::wall_offset(scene) + scene.wall_spacing;
      clamp = {scene.box.lo - Vec3d{reach, reach, reach}, scene.box.hi + Vec3d{reach, reach, reach}};
    }
    box = boundary::BoxCollision<Real>{clamp.template cast<Real>(), Real(scene.restitution)};
  }
  std::unique_ptr<integrate::Stepper<Real>> stepper;
  std::unique_ptr<sph::SphFluid<Real>> fluid;
  if (scene.sph)
    fluid = std::make_unique<sph::SphFluid<Real>>(
        *scene.sph, sph::StepConditions{scene.cfl, scene.force_factor, scene.viscous_factor});
  if (fluid && fluid->dfsph())  // the stepper drives the fluid's solves; the simulation owns both
    stepper = std::make_unique<sph::DfsphStepper<Real>>(*fluid, std::move(box));
  else if (scene.time_steps == scene::TimeSteps::Block)
    stepper = std::make_unique<integrate::BlockStepper<Real>>(
        integrate::BlockStepOptions{scene.eta, scene.nbody->softening, int(scene.max_bin)});
  else
    stepper = std::make_unique<integrate::KickDriftStepper<Real>>(integrate::Method::VelocityVerlet, std::move(box));
  // Moving obstacles: their particles' rest positions, as make_particles
  // sampled them, by id (boundary/moving_boundaries.hpp).
  std::vector<boundary::MovingObstacle> moving;
  const std::vector<scene::ObstacleIds> ids = scene::obstacle_ids(scene);
  std::size_t k = 0;
  for (const auto& source : scene.sources)
    if (const auto* o = std::get_if<scene::ObstacleSource>(&source)) {
      if (o->motion) moving.push_back({ids.at(k).first, scene::obstacle_points(*o), *o->motion});
      ++k;
    }
  if (fluid && !moving.empty()) fluid->set_moving_boundaries(true);
  Simulation<Real> sim(std::move(particles), settings, std::move(stepper));
  if (!moving.empty()) sim.set_moving_boundaries(std::make_shared<const boundary::MovingBoundaries>(std::move(moving)));
  if (fluid) sim.add_solver(std::move(fluid));
  if (scene.nbody)
    sim.add_solver(std::make_unique<gravity::GravityForce<Real>>(
        *scene.nbody, gravity::SelfGravityOptions{scene.gravitational_constant, scene.eta}));
  if (!(scene.gravity == Vec3d{})) sim.add_solver(std::make_unique<UniformGravity<Real>>(scene.gravity.template cast<Real>()));
  if (scene.damping > 0) sim.add_solver(std::make_unique<Damping<Real>>(scene.damping));
  return sim;
}

template <class Real>
Simulation<Real> build_simulation(const scene::Scene& scene) {
  return build_simulation<Real>(scene, scene::make_particles<Real>(scene));
}

}  // namespace swirl::sim
