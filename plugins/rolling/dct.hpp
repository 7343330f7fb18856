// SPDX-License-Identifier: MIT
// Rolling slot "dct": the directional constant torque model (Ai et al. 2011
// "model A"; LIGGGHTS rolling_model_cdt; docs/physics.md §2.1, §3.8):
//   M = - mu_r R* |F_n,el| omega_r / |omega_r|
// with omega_r the rolling part of the relative angular velocity. mu_r is
// given directly ("rolling_friction") or as tan(theta_c) ("critical_angle")
// for like-for-like comparisons with sd_critical_angle (Ai et al.: mu_r = tan beta).
// Known defect kept on purpose (it is what the comparison shows): the torque
// does not vanish as omega_r -> 0, so a particle at rest chatters with
// |delta omega| ~ M dt / I every step. No history.
#pragma once

#include <domel/sdk/kinematics.hpp>
#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace domel::plugins::rolling {

using sdk::cap_force;
using sdk::rolling_velocity;
using sdk::Vec3;

class Dct {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
  static constexpr const char* kName = "dct";
  static constexpr const char* kVersion = "1.0.1";
  static constexpr const char* kSummary =
      "directional constant rolling torque mu_r R* |F_n| opposing the relative rolling (Ai et al. 2011 model A)";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Constant-magnitude rolling torque opposing the relative rolling velocity. Give exactly one of rolling_friction or critical_angle.",
  "properties": {
    "rolling_friction": { "type": "number", "minimum": 0, "x-unit": "1",
                          "description": "coefficient of rolling friction mu_r" },
    "critical_angle": { "type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 90, "x-unit": "deg",
                        "description": "critical rolling angle theta_c; mu_r = tan(theta_c)" }
  },
  "oneOf": [ { "required": ["rolling_friction"] }, { "required": ["critical_angle"] } ],
  "additionalProperties": false
})json";

  explicit Dct(const sdk::Params& p) {
    const bool by_mu = p.has("rolling_friction"), by_angle = p.has("critical_angle");
    if (by_mu == by_angle) throw sdk::ParameterError("dct: give exactly one of 'rolling_friction' or 'critical_angle'");
    mu_r_ = by_mu ? p.number("rolling_friction") : std::tan(p.number("critical_angle") * M_PI / 180.0);
  }

  void compute(domel_contact_batch_v2& b) const {
    // the pair's mu_r when the scenario sets one for this material pair (abi.h)
    const double mu_r = b.pair->has_rolling_friction != 0 ? b.pair->rolling_friction : mu_r_;
    kernel(b.n, mu_r, b.r_eff, b.fn_elastic, b.nx, b.ny, b.nz, b.wx, b.wy, b.wz, b.tqx, b.tqy, b.tqz);
  }

 private:
  // __restrict parameters and a select instead of `continue`: the loop vectorises.
  static void kernel(uint32_t n, double mu_r, const double* __restrict r_eff, const double* __restrict fn_el,
                     const double* __restrict nx, const double* __restrict ny, const double* __restrict nz,
                     const double* __restrict wx, const double* __restrict wy, const double* __restrict wz,
                     double* __restrict tqx, double* __restrict tqy, double* __restrict tqz) {
    for (uint32_t c = 0; c < n; ++c) {
      const Vec3 w = rolling_velocity(wx[c], wy[c], wz[c], nx[c], ny[c], nz[c]);
      const double len = std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z);
      // No rolling: also when only round-off of removing a pure twist is left
      // (its direction would be random and the torque is full-size).
      const double full = std::sqrt(wx[c] * wx[c] + wy[c] * wy[c] + wz[c] * wz[c]);
      const bool rolling = (len > 1e-12 * full) & (len != 0.0);
      const double cap = cap_force(fn_el[c]);
      // every contact takes the same arithmetic (times 0 when not rolling), so no load or division is conditional
      const double m = (rolling ? 1.0 : 0.0) * (mu_r * r_eff[c] * cap / (rolling ? len : 1.0));
      tqx[c] -= m * w.x; tqy[c] -= m * w.y; tqz[c] -= m * w.z;
    }
  }

  double mu_r_ = 0.0;
};

}  // namespace domel::plugins::rolling
