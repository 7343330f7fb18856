// SPDX-License-Identifier: MIT
// The time step of a subdomain from its contact model: the Rayleigh time of
// the smallest particle, the duration of a head-on collision at the impact
// velocity and the explicit stability limit of the stiffest contact
// (particle-particle and each wall; a rolling spring's own limit included),
// all found by integrating a collision with the pipeline's own stages, so
// a plugin's law sets its own step (docs/physics.md §1.3, §3.6).
#pragma once

#include "contact/contact_pipeline.hpp"
#include "core/material.hpp"
#include "core/particle_store.hpp"
#include "geometry/wall.hpp"

#include <optional>
#include <string>
#include <vector>

namespace domel::platform {

struct TimeStepReport {
  double rayleigh = 0;       ///< Rayleigh time of the smallest particle [s]
  double contact_time = 0;   ///< shortest simulated collision at the impact velocity [s]
  double critical = 0;       ///< explicit stability limit 2/omega (damped) of the stiffest contact [s]
  std::string critical_of;   ///< which contact sets it ("particle-particle", "wall 'x'")
  /// The contacts that did not stop the impact before the centres met (a
  /// wall: the centre reached its surface), comma-separated; their contact
  /// time is the time to that point. Empty when every contact stopped it.
  std::string passes_through;
  double chosen = 0;         ///< [s]
  std::string reason;
};

/// The contacts a time step is estimated for.
struct TimeStepInputs {
  ContactPipeline* pipeline;
  const std::vector<Material>* materials;        ///< the subdomain's, by local index (ParticleStore::material)
  const std::vector<domel_pair_v2>* pairs;       ///< [a * n + b]
  const std::vector<domel_pair_v2>* wall_pairs;  ///< [w * n + a]
  const std::vector<WallPrimitive>* walls;       ///< names, for the report
  const std::vector<const ModelInstance*>* pair_rolling;       ///< each pair's rolling model, as pairs
  const std::vector<const ModelInstance*>* wall_pair_rolling;  ///< as wall_pairs
};

/// Rayleigh time, contact time and stability limit at `impact_velocity`
/// (chosen and reason left empty): for each material present, its smallest
/// particle of `s`, colliding with the smallest of every material (itself
/// included) and with every wall; the shortest times are reported. Throws
/// PluginError when a stage fails.
TimeStepReport estimate_time_step(const TimeStepInputs& in, const ParticleStore& s, double impact_velocity);

/// What is wrong with a given time step, and how to fix it (empty: nothing).
struct TimeStepProblem {
  std::string message, hint;
  explicit operator bool() const { return !message.empty(); }
};

/// Fill rep.chosen and rep.reason. A given step is checked against the
/// stability limit; without one the choice is min(0.2 x Rayleigh time,
/// contact time / 50, half the stability limit) (docs/physics.md §1.3).
/// `estimated` is false when there was no particle to estimate with; a
/// step must then be given.
TimeStepProblem choose_time_step(const std::string& subdomain, TimeStepReport& rep, std::optional<double> given,
                                 bool estimated, double impact_velocity);

}  // namespace domel::platform
