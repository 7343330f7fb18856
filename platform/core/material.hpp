// SPDX-License-Identifier: MIT
// Materials and material pairs. A material carries the intrinsic constants;
// the pair constants handed to contact kernels (E*, G*, e, mu) are derived
// here with the Hertz–Mindlin effective-modulus rules (docs/physics.md §1.1).
#pragma once

#include <domel/sdk/abi.h>

#include <string>

namespace domel::platform {

struct Material {
  std::string name;
  double density = 0.0;         ///< [kg/m^3]
  double youngs_modulus = 0.0;  ///< [Pa]
  double poisson_ratio = 0.0;   ///< [-]
};

/// Restitution, friction, (when the scenario gives it) the rolling friction
/// and which rolling model acts, of one pair of materials.
struct PairCoefficients {
  double restitution = 0.0;
  double friction = 0.0;
  double rolling_friction = 0.0;  ///< mu_r of the pair; valid when has_rolling_friction
  bool has_rolling_friction = false;
  /// The pair's rolling model: the subdomain's (-1), none (-2) or the k-th
  /// of the models interactions name (ContactPipeline::rolling_model).
  int rolling_model = -1;
};

/// 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j ; 1/G* = 2(2-nu_i)(1+nu_i)/E_i + (same for j).
inline domel_pair_v2 make_pair(const Material& a, const Material& b, const PairCoefficients& c,
                               bool is_wall, double coarse_grain) {
  domel_pair_v2 p{};
  p.struct_size = sizeof(domel_pair_v2);
  p.is_wall = is_wall ? 1u : 0u;
  p.youngs_eff = 1.0 / ((1.0 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus +
                        (1.0 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus);
  p.shear_eff = 1.0 / (2.0 * (2.0 - a.poisson_ratio) * (1.0 + a.poisson_ratio) / a.youngs_modulus +
                       2.0 * (2.0 - b.poisson_ratio) * (1.0 + b.poisson_ratio) / b.youngs_modulus);
  p.restitution = c.restitution;
  p.friction = c.friction;
  p.coarse_grain = coarse_grain;
  // not given: the rolling model's own parameter applies (abi.h)
  p.rolling_friction = c.has_rolling_friction ? c.rolling_friction : 0.0;
  p.has_rolling_friction = c.has_rolling_friction ? 1u : 0u;
  return p;
}

}  // namespace domel::platform
