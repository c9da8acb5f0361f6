// Building the Simulation a scene describes: its particles, its box and its
// force models (SPH when the scene has [sph], self-gravity with [nbody],
// uniform gravity when non-zero). Without walls the space is open.
// Shared by run_scene() and the tools that inspect a scene (hash-stats).
#pragma once

#include <memory>

#include "swirl/force/uniform_gravity.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/scene.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/sph_fluid.hpp"

namespace swirl::sim {

template <class Real>
struct SceneSimulation {
  Simulation<Real> sim;
  sph::SphFluid<Real>* fluid = nullptr;             // owned by sim; null without [sph]
  gravity::GravityForce<Real>* self_gravity = nullptr;  // owned by sim; null without [nbody]
};

template <class Real>
SceneSimulation<Real> build_simulation(const scene::Scene& scene) {
  SimulationSettings settings;
  settings.dt = scene.dt;
  settings.block_size = scene.block_size;
  if (scene.walls) settings.box = boundary::BoxCollision<double>{scene.box, scene.restitution};
  // Time-step conditions and the blow-up guard (sim/step_limits.hpp, docs/stability.md).
  settings.adaptive = scene.adaptive_dt;
  settings.dt_min = scene.dt_min;
  if (scene.sph) {
    settings.limits.sph = sim::SphStepLimits{scene.sph->smoothing_length, scene.sph->sound_speed, scene.sph->viscosity,
                                             scene.cfl, scene.force_factor, scene.viscous_factor};
    if (scene.walls) settings.escape_length = scene.sph->smoothing_length;
  }
  if (scene.nbody) settings.limits.gravity = sim::GravityStepLimits{scene.nbody->softening, scene.eta};
  SceneSimulation<Real> out{Simulation<Real>(scene::make_particles<Real>(scene), settings)};
  if (scene.sph) {
    auto model = std::make_unique<sph::SphFluid<Real>>(*scene.sph);
    out.fluid = model.get();
    out.sim.add_force(std::move(model));
  }
  if (scene.nbody) {
    auto model = std::make_unique<gravity::GravityForce<Real>>(*scene.nbody);
    out.self_gravity = model.get();
    out.sim.add_force(std::move(model));
  }
  if (!(scene.gravity == Vec3d{}))
    out.sim.add_force(std::make_unique<UniformGravity<Real>>(scene.gravity.template cast<Real>()));
  return out;
}

}  // namespace swirl::sim
