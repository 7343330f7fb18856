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

#include <domel/sdk/kinematics.hpp>
#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace domel::plugins::rolling {

using sdk::cap_force;
using sdk::rolling_velocity;
using sdk::tangent_keep_length;
using sdk::Vec3;

class SdCriticalAngle {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
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

  void compute(domel_contact_batch_v2& b) const {
    // The pair's mu_r = tan(theta_c) when the scenario sets one for this
    // material pair (abi.h, domel_pair_v2::rolling_friction), else ours.
    const double tan_c = b.pair->has_rolling_friction != 0 ? b.pair->rolling_friction : tan_c_;
    // Two passes, so that the common case (elastic) runs vectorised and
    // without divisions: the elastic pass, then the few yielded contacts
    // redone from the angle it stored (the same expressions, so the results
    // are those of a one-pass if/else loop bit for bit, the sign of a zero
    // torque aside).
    const uint32_t s = b.history_stride;
    double yield[kChunk];
    for (uint32_t c0 = 0; c0 < b.n; c0 += kChunk) {
      const uint32_t m = b.n - c0 < kChunk ? b.n - c0 : kChunk;
      const double* kn = tangent_ ? b.kn_tangent : b.kn;
      const double yields =
          elastic_pass(m, s, b.dt, tan_c, b.r_eff + c0, kn + c0, b.eta_n + c0, b.fn_elastic + c0, b.nx + c0,
                       b.ny + c0, b.nz + c0, b.wx + c0, b.wy + c0, b.wz + c0, b.history + static_cast<size_t>(c0) * s,
                       b.tqx + c0, b.tqy + c0, b.tqz + c0, b.rolling_stiffness + c0, b.rolling_damping + c0, yield);
      if (yields == 0.0) continue;
      for (uint32_t q = 0; q < m; ++q) {
        if (yield[q] == 0.0) continue;
        const uint32_t c = c0 + q;
        double* th = b.history + static_cast<size_t>(c) * s;  // holds the new angle
        const Constants p = constants(b.r_eff[c], kn[c], b.eta_n[c], b.fn_elastic[c], tan_c);
        const double k = p.k, eta = p.eta, m_ref = p.m_ref;
        const Vec3 w = rolling_velocity(b.wx[c], b.wy[c], b.wz[c], b.nx[c], b.ny[c], b.nz[c]);
        double m0 = -k * th[0], m1 = -k * th[1], m2 = -k * th[2];
        const double ms = std::sqrt(m0 * m0 + m1 * m1 + m2 * m2);
        const double scale = m_ref / ms;  // ms^2 > m_ref^2 >= 0, so ms > 0
        m0 *= scale; m1 *= scale; m2 *= scale;
        if (k > 0.0) { th[0] = -m0 / k; th[1] = -m1 / k; th[2] = -m2 / k; }
        else { th[0] = th[1] = th[2] = 0.0; }
        if (damping_at_yield_) { m0 -= eta * w.x; m1 -= eta * w.y; m2 -= eta * w.z; }
        b.tqx[c] += m0; b.tqy[c] += m1; b.tqz[c] += m2;
      }
    }
  }

 private:
  static constexpr uint32_t kChunk = 256;

  // The contact's rolling constants from theta_c (the header's formulas,
  // docs/physics.md §3.1-§3.3): spring k_th = k_n a^2/4, dashpot
  // n_th = eta_n a^2/4, cap M_ref = a F_cap, with a = R* tan(theta_c).
  struct Constants {
    double k, eta, m_ref;
  };
  static Constants constants(double r_eff, double kn, double eta_n, double fn_el, double tan_c) {
    const double a = r_eff * tan_c;
    return {0.25 * kn * a * a, 0.25 * eta_n * a * a, a * cap_force(fn_el)};
  }  // contacts per elastic pass (a stack array of yield flags)

  // Pass 1: every contact as if elastic; a yield flag (1.0/0.0) per contact;
  // yielded contacts add no torque here. A free function with __restrict
  // parameters (GCC ignores restrict on local pointers) and no branches, so
  // that the loop vectorises. Returns the number of yielded contacts.
  static double elastic_pass(uint32_t n, uint32_t s, double dt, double tan_c, const double* __restrict r_eff,
                             const double* __restrict kn, const double* __restrict eta_n,
                             const double* __restrict fn_el, const double* __restrict nx,
                             const double* __restrict ny, const double* __restrict nz, const double* __restrict wx,
                             const double* __restrict wy, const double* __restrict wz, double* __restrict hist,
                             double* __restrict tqx, double* __restrict tqy, double* __restrict tqz,
                             double* __restrict k_out, double* __restrict eta_out, double* __restrict yield) {
    double yields = 0.0;
    for (uint32_t c = 0; c < n; ++c) {
      double* th = hist + static_cast<size_t>(c) * s;
      const Constants p = constants(r_eff[c], kn[c], eta_n[c], fn_el[c], tan_c);
      const double k = p.k, eta = p.eta, m_ref = p.m_ref;
      const double n0 = nx[c], n1 = ny[c], n2 = nz[c];
      const Vec3 w = rolling_velocity(wx[c], wy[c], wz[c], n0, n1, n2);
      // the stored angle carried into the current tangent plane, its length
      // kept (sdk/kinematics.hpp, physics.md §3.4), then the increment
      const Vec3 t = tangent_keep_length(th[0], th[1], th[2], n0, n1, n2);
      const double t0 = t.x + w.x * dt, t1 = t.y + w.y * dt, t2 = t.z + w.z * dt;
      const double m0 = -k * t0, m1 = -k * t1, m2 = -k * t2;
      const double ms_sq = m0 * m0 + m1 * m1 + m2 * m2;
      const double flag = ms_sq > m_ref * m_ref ? 1.0 : 0.0;  // above the cap: redone in the second pass
      yield[c] = flag;
      yields += flag;
      const double elastic = 1.0 - flag;
      th[0] = t0; th[1] = t1; th[2] = t2;
      tqx[c] += elastic * (m0 - eta * w.x);  // spring and dashpot while elastic
      tqy[c] += elastic * (m1 - eta * w.y);
      tqz[c] += elastic * (m2 - eta * w.z);
      k_out[c] = k;
      eta_out[c] = eta;
    }
    return yields;
  }

  double tan_c_;
  bool tangent_;
  bool damping_at_yield_;
};

}  // namespace domel::plugins::rolling
