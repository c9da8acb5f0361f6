// Helpers shared by the simulation tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/force/solver.hpp"
#include "swirl/gravity/gravity_force.hpp"
#include "swirl/sim/simulation.hpp"
#include "swirl/sph/sph_fluid.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::testing {

// a = -ω²·(x - centre): a harmonic oscillator about `centre` on every axis.
template <class Real>
class Spring final : public Solver<Real> {
 public:
  Spring(Real omega, Real centre) : omega2_(omega * omega), centre_(centre) {}
  std::string_view name() const override { return "spring"; }
  void add_acceleration(ParticleSet<Real>& p, const SolverContext<Real>& ctx) override {
    parallel::for_blocks("spring", p.size(), ctx.block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (int axis = 0; axis < 3; ++axis)
        for (std::size_t i = b; i < e; ++i) p.acceleration[axis][i] += -omega2_ * (p.position[axis][i] - centre_);
    });
  }

 private:
  Real omega2_, centre_;
};

// The time-step conditions of a real solver without its forces: the guard's
// tests drive the conditions with simple forces (a spring, a field).
template <class Real>
class ConditionsOf final : public Solver<Real> {
 public:
  explicit ConditionsOf(std::unique_ptr<Solver<Real>> inner) : inner_(std::move(inner)) {}
  std::string_view name() const override { return inner_->name(); }
  void add_acceleration(ParticleSet<Real>&, const SolverContext<Real>&) override {}
  ScanNeeds scan_needs() const override { return inner_->scan_needs(); }
  void add_limits(const StepScan& scan, std::size_t n, std::vector<StepLimit>& out) const override {
    inner_->add_limits(scan, n, out);
  }
  LimitText explain(const StepLimit& limit, std::string_view particle) const override {
    return inner_->explain(limit, particle);
  }
  std::string advice() const override { return inner_->advice(); }

 private:
  std::unique_ptr<Solver<Real>> inner_;
};

// The SPH conditions for h, c, μ (and the constants C_cfl, C_force, C_visc).
template <class Real>
std::unique_ptr<Solver<Real>> sph_conditions(double h, double c, double mu, double cfl = 0.6, double force = 0.4,
                                             double viscous = 0.125) {
  sph::SphParameters p;
  p.smoothing_length = h;
  p.sound_speed = c;
  p.viscosity = mu;
  return std::make_unique<ConditionsOf<Real>>(
      std::make_unique<sph::SphFluid<Real>>(p, sph::StepConditions{cfl, force, viscous}));
}

// The gravity condition for softening ε and factor η.
template <class Real>
std::unique_ptr<Solver<Real>> gravity_conditions(double softening, double eta) {
  gravity::GravitySettings g;
  g.softening = softening;
  return std::make_unique<ConditionsOf<Real>>(
      std::make_unique<gravity::GravityForce<Real>>(g, gravity::SelfGravityOptions{1, eta}));
}

// The current limit of the condition `name` (dt = ∞ when the solvers made none).
template <class Real>
StepLimit limit_named(const Simulation<Real>& sim, std::string_view name) {
  for (const auto& l : sim.limits())
    if (l.condition == name) return l;
  return {};
}

// A deterministic pseudo-random number in [0, 1) from an integer.
inline double hash01(std::uint64_t k) {
  k += 0x9e3779b97f4a7c15ull;
  k = (k ^ (k >> 30)) * 0xbf58476d1ce4e5b9ull;
  k = (k ^ (k >> 27)) * 0x94d049bb133111ebull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53;
}

}  // namespace swirl::testing
