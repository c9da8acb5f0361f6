// GravityForce<Real>: self-gravity as a ForceModel (G = 1 N-body units).
//
// Each call computes the field of the particles (direct sum or Barnes–Hut with
// the configured scheme), adds a_i to particles.acceleration and writes φ_i
// into the extra field "potential" (added on first use), so W = ½ Σ m_i φ_i
// comes from the same walk as the force (potential_energy() in diagnostics.hpp).
// If ctx.timers is set, the time is recorded as the sub-phases "forces.tree_build"
// and "forces.walk" (inside the stepper's "forces" phase). Holds the state of the
// sub-domain load balance (the previous evaluation's work per tree) and the
// last evaluation's statistics.
//
// With the linear tree and settings.reorder (the default), each call first
// reorders the particles along the Morton curve (ParticleSet::reorder: every
// field moves, ids survive), so the index of a particle changes between calls.
//
// Results are bit-identical for any thread count.
#pragma once

#include <string_view>

#include "swirl/force/force_model.hpp"
#include "swirl/gravity/barnes_hut.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/settings.hpp"

namespace swirl::gravity {

template <class Real>
class GravityForce final : public ForceModel<Real> {
 public:
  // Validates the settings: std::invalid_argument names a bad parameter.
  explicit GravityForce(const GravitySettings& settings = {});

  std::string_view name() const override { return "self_gravity"; }
  void add_acceleration(ParticleSet<Real>& particles, const ForceContext& ctx) override;

  const GravitySettings& settings() const { return settings_; }
  // The last evaluation: nodes visited per particle (N − 1 for the direct sum), trees, times.
  const GravityStats& stats() const { return stats_; }
  // The last evaluation's field.
  const GravityField<Real>& field() const { return field_; }

 private:
  GravitySettings settings_;
  BarnesHut<Real> tree_;
  GravityField<Real> field_;
  GravityStats stats_;
};

extern template class GravityForce<float>;
extern template class GravityForce<double>;

}  // namespace swirl::gravity
