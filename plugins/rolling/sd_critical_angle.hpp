// SPDX-License-Identifier: MIT
// Rolling slot "sd_critical_angle": the single-parameter spring–dashpot
// rolling model (Widartiningsih et al. 2026, arXiv 2602.15887, as
// reconstructed in docs/physics.md §3; all [RECON]). One parameter, the
// critical rolling angle theta_c, fixes everything from the contact's own
// R*, k_n, eta_n and F_n:
//   a     = R* tan(theta_c)                 moment arm, from the incline balance (§3.1)
//   k_th  = k_n a^2 / 4                     spring bed over a disk of radius a (§2.6, §3.3)
//   n_th  = eta_n a^2 / 4                   dashpot bed, same integral (§3.3)
//   M_ref = R* tan(theta_c) |F_n,el|        torque cap (§3.2)
// Incremental law (§3.4): the stored rolling angle theta_r is projected onto
// the current tangent plane (its length kept), theta_r += omega_r dt,
// M_s = -k_th theta_r; above the cap M_s is scaled to M_ref and theta_r
// rescaled so that k_th |theta_r| = M_ref (plastic slip); M = M_s + M_d with
// M_d = -n_th omega_r while elastic.
// Choices the sources leave open (docs/rolling.md):
//  - k_n is the TANGENT normal stiffness dF/d delta by default (the incremental
//    stiffness a small tilt actually meets; 1.5x the secant one for Hertz);
//    "normal_stiffness": "secant" selects F/delta.
//  - the dashpot is OFF once the spring is fully mobilised (Ai et al. 2011's
//    f = 0, as LIGGGHTS epsd); "damping_at_yield": true keeps it.
// History: 3 doubles, the rolling angle vector theta_r [rad].
// Because everything scales with the parcel's own R*, k_n and F_n, theta_c
// is preserved under coarse-graining (§3.7, "implementation recommendation").
#pragma once

#include "rolling_common.hpp"

#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace domel::plugins::rolling {

class SdCriticalAngle {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr const char* kName = "sd_critical_angle";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary =
      "single-parameter spring-dashpot rolling resistance from the critical rolling angle theta_c";
  static constexpr unsigned kHistorySlots = 3;
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Spring-dashpot rolling resistance with one physical parameter, the critical rolling angle: the steepest incline on which a sphere stays at rest. Stiffness, damping and torque cap follow from it and the normal contact.",
  "properties": {
    "critical_angle": { "type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 90, "x-unit": "deg",
                        "description": "critical rolling angle theta_c" },
    "normal_stiffness": { "enum": ["tangent", "secant"], "default": "tangent",
                          "description": "which normal stiffness k_n sets k_theta = k_n a^2/4: tangent dF/d(delta) or secant F/delta (equal for a linear spring)" },
    "damping_at_yield": { "type": "boolean", "default": false,
                          "description": "keep the rolling dashpot while the spring is fully mobilised (default: off, Ai et al. 2011)" }
  },
  "required": ["critical_angle"],
  "additionalProperties": false
})json";

  explicit SdCriticalAngle(const sdk::Params& p)
      : tan_c_(std::tan(p.number("critical_angle") * M_PI / 180.0)),
        tangent_(p.string_or("normal_stiffness", "tangent") == "tangent"),
        damping_at_yield_(p.boolean_or("damping_at_yield", false)) {
    const double deg = p.number("critical_angle");
    if (!(deg > 0.0 && deg < 90.0))
      throw sdk::ParameterError("sd_critical_angle: critical_angle must lie in (0, 90) degrees");
  }

  void compute(domel_contact_batch_v1& b) const {
    // The batch arrays as local pointers and the branches as selects (the
    // results are bit-identical to the if/else form): GCC reloads pointers
    // read through `b` on every iteration and keeps branchy loops scalar.
    const uint32_t s = b.history_stride;
    const uint32_t n = b.n;
    const double dt = b.dt;
    const double tan_c = tan_c_;
    const bool damp_at_yield = damping_at_yield_;
    const double* __restrict r_eff = b.r_eff;
    const double* __restrict kn_used = tangent_ ? b.kn_tangent : b.kn;
    const double* __restrict eta_n = b.eta_n;
    const double* __restrict fn_el = b.fn_elastic;
    const double* __restrict nx = b.nx; const double* __restrict ny = b.ny; const double* __restrict nz = b.nz;
    const double* __restrict wx = b.wx; const double* __restrict wy = b.wy; const double* __restrict wz = b.wz;
    double* __restrict hist = b.history;
    double* __restrict tqx = b.tqx; double* __restrict tqy = b.tqy; double* __restrict tqz = b.tqz;
    double* __restrict k_out = b.rolling_stiffness;
    double* __restrict eta_out = b.rolling_damping;
    for (uint32_t c = 0; c < n; ++c) {
      double* th = hist + static_cast<size_t>(c) * s;
      const double a = r_eff[c] * tan_c;
      const double k = 0.25 * kn_used[c] * a * a;
      const double eta = 0.25 * eta_n[c] * a * a;
      const double m_ref = a * (fn_el[c] > 0.0 ? fn_el[c] : 0.0);  // cap from the non-negative elastic force
      // relative rolling velocity: the tangential part of w_i - w_j
      const double ux = nx[c], uy = ny[c], uz = nz[c];
      const double wn = wx[c] * ux + wy[c] * uy + wz[c] * uz;
      const double vx = wx[c] - wn * ux, vy = wy[c] - wn * uy, vz = wz[c] - wn * uz;
      // history projected onto the current tangent plane, its length kept
      const double h0 = th[0], h1 = th[1], h2 = th[2];
      const double len0 = std::sqrt(h0 * h0 + h1 * h1 + h2 * h2);
      const double proj = h0 * ux + h1 * uy + h2 * uz;
      const double p0 = h0 - proj * ux, p1 = h1 - proj * uy, p2 = h2 - proj * uz;
      const double len1 = std::sqrt(p0 * p0 + p1 * p1 + p2 * p2);
      const bool rescale = len1 > 0.0;
      const double keep = len0 / (rescale ? len1 : 1.0);
      const double t0 = (rescale ? p0 * keep : p0) + vx * dt;
      const double t1 = (rescale ? p1 * keep : p1) + vy * dt;
      const double t2 = (rescale ? p2 * keep : p2) + vz * dt;
      const double m0 = -k * t0, m1 = -k * t1, m2 = -k * t2;
      const double ms = std::sqrt(m0 * m0 + m1 * m1 + m2 * m2);
      const bool yielded = ms > m_ref;  // then ms > 0
      const double scale = m_ref / (yielded ? ms : 1.0);
      const double y0 = m0 * scale, y1 = m1 * scale, y2 = m2 * scale;
      const bool has_k = k > 0.0;
      const double kd = has_k ? k : 1.0;
      const double e0 = has_k ? -y0 / kd : 0.0, e1 = has_k ? -y1 / kd : 0.0, e2 = has_k ? -y2 / kd : 0.0;
      th[0] = yielded ? e0 : t0;  // plastic rescale: k|theta| = M_ref
      th[1] = yielded ? e1 : t1;
      th[2] = yielded ? e2 : t2;
      const bool damp = !yielded || damp_at_yield;
      const double d = damp ? eta : 0.0;
      tqx[c] += (yielded ? y0 : m0) - d * vx;
      tqy[c] += (yielded ? y1 : m1) - d * vy;
      tqz[c] += (yielded ? y2 : m2) - d * vz;
      k_out[c] = k;
      eta_out[c] = eta;
    }
  }

 private:
  double tan_c_;
  bool tangent_;
  bool damping_at_yield_;
};

}  // namespace domel::plugins::rolling
