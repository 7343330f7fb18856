// SPDX-License-Identifier: MIT
//
// Rolling slot "epsd": the elastic-plastic spring-dashpot rolling resistance
// of Ai, Chen, Rotter & Ooi (2011), "Assessment of rolling resistance models
// in discrete element simulations", Powder Technol. 206, 269-282 ("model C"),
// as LIGGGHTS computes it (rolling_model_epsd.h; project physics reference
// /work/shared/docs/physics.md §2.2). A third-party plugin: it is built
// against the INSTALLED domel SDK only (see CMakeLists.txt, README.md and
// docs/tutorial-rolling-plugin.md, whose code is this file).
//
// Per contact and time step, with omega_r the rolling part of the relative
// angular velocity omega_i - omega_j:
//   k_r   = 2.25 k_n mu_r^2 R*^2          rolling spring (Jiang et al. 2005's
//                                         contact width, via Ai et al. 2011)
//   M_k  += k_r omega_r dt                spring torque, kept in the history
//   M_max = mu_r R* F_n                   plastic limit
//   |M_k| > M_max:  M_k <- M_k M_max/|M_k|, stored; M = M_k   (no dashpot: Ai's f = 0)
//   otherwise:      M = M_k + C_r omega_r,  C_r = eta_r 2 sqrt(I_r k_r)
//   torque on i: -M (the host gives j +M)
// Choices where the batch or the sources leave room (all documented in the
// tutorial):
//  - k_n is the normal model's secant stiffness `kn` = F_el/delta, which is
//    what LIGGGHTS hands the rolling model (cdata.kn, 4/3 E* sqrt(R* delta)
//    for Hertz).
//  - F_n is the total normal force `fn` (elastic + dashpot) that the host sums
//    before the tangential stage, as LIGGGHTS's cdata.Fn; a net attractive
//    value counts as 0 (LIGGGHTS with limitForce).
//  - The stored M_k is rotated into the current tangent plane (projected, its
//    length kept) before the increment, so that it never acquires a twisting
//    component. LIGGGHTS stores it unrotated.
//  - I_r needs the two masses, the batch gives m* and the radii: see
//    rolling_inertia() below.
// History: 3 doubles, the spring torque M_k [N m].
#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace {

class Epsd {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr const char* kName = "epsd";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary =
      "elastic-plastic spring-dashpot rolling resistance (Ai et al. 2011 model C, as LIGGGHTS epsd)";
  static constexpr unsigned kHistorySlots = 3;  // M_k, the spring torque vector
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Elastic-plastic spring-dashpot (EPSD) rolling resistance of Ai et al. (2011), model C: an incremental rolling spring k_r = 2.25 k_n mu_r^2 R*^2 capped at mu_r R* F_n, plus a dashpot while the spring is below the cap.",
  "properties": {
    "rolling_friction": { "type": "number", "minimum": 0, "x-unit": "1",
                          "description": "coefficient of rolling friction mu_r: the torque cap is mu_r R* F_n" },
    "viscous_damping": { "type": "number", "minimum": 0, "default": 0, "x-unit": "1",
                         "description": "rolling viscous damping ratio eta_r: C_r = eta_r 2 sqrt(I_r k_r)" }
  },
  "required": ["rolling_friction"],
  "additionalProperties": false
})json";

  explicit Epsd(const domel::sdk::Params& p)
      : mu_r_(p.number("rolling_friction")), eta_r_(p.number_or("viscous_damping", 0.0)) {
    // The schema already says >= 0; the constructor also refuses NaN and
    // guards a host that did not validate.
    if (!(mu_r_ >= 0.0))
      throw domel::sdk::ParameterError("epsd: 'rolling_friction' must be a number >= 0");
    if (!(eta_r_ >= 0.0))
      throw domel::sdk::ParameterError("epsd: 'viscous_damping' must be a number >= 0");
  }

  // Called from several threads at once on the same instance (abi.h):
  // const, and every per-contact state lives in b.history.
  void compute(domel_contact_batch_v1& b) const {
    const uint32_t stride = b.history_stride;
    for (uint32_t c = 0; c < b.n; ++c) {
      const double nx = b.nx[c], ny = b.ny[c], nz = b.nz[c];

      // omega_r: the rolling part of omega_i - omega_j (the part about n is twisting).
      const double wn = b.wx[c] * nx + b.wy[c] * ny + b.wz[c] * nz;
      const double wrx = b.wx[c] - wn * nx, wry = b.wy[c] - wn * ny, wrz = b.wz[c] - wn * nz;

      // Spring, dashpot and cap of this contact.
      const double r = b.r_eff[c];
      const double k_r = 2.25 * b.kn[c] * mu_r_ * mu_r_ * r * r;
      const double c_r = eta_r_ * 2.0 * std::sqrt(rolling_inertia(b, c) * k_r);
      const double f_n = b.fn[c] > 0.0 ? b.fn[c] : 0.0;
      const double m_max = mu_r_ * r * f_n;

      // M_k from the history, rotated into the current tangent plane.
      double* h = b.history + static_cast<size_t>(c) * stride;
      double mx = h[0], my = h[1], mz = h[2];
      const double len_old = std::sqrt(mx * mx + my * my + mz * mz);
      const double mn = mx * nx + my * ny + mz * nz;
      mx -= mn * nx; my -= mn * ny; mz -= mn * nz;
      const double len_new = std::sqrt(mx * mx + my * my + mz * mz);
      if (len_new > 0.0) {
        const double keep = len_old / len_new;
        mx *= keep; my *= keep; mz *= keep;
      }

      // Incremental spring: M_k += k_r omega_r dt.
      mx += k_r * wrx * b.dt; my += k_r * wry * b.dt; mz += k_r * wrz * b.dt;

      // Plastic cap, or the dashpot while elastic.
      const double len = std::sqrt(mx * mx + my * my + mz * mz);
      double tx, ty, tz;  // M, the resisting moment before the sign
      if (len > m_max) {
        const double scale = m_max / len;  // len > m_max >= 0
        mx *= scale; my *= scale; mz *= scale;
        tx = mx; ty = my; tz = mz;  // fully mobilised: no dashpot (Ai et al.'s f = 0)
      } else {
        tx = mx + c_r * wrx; ty = my + c_r * wry; tz = mz + c_r * wrz;
      }
      h[0] = mx; h[1] = my; h[2] = mz;

      // The couple on i is -M, added to what earlier stages wrote; j gets +M from the host.
      b.tqx[c] -= tx; b.tqy[c] -= ty; b.tqz[c] -= tz;

      // For the host's rotational time-step check (ABI 1.1).
      b.rolling_stiffness[c] = k_r;
      b.rolling_damping[c] = c_r;
    }
  }

 private:
  // I_r = 1.4 (m_i R_i^2)(m_j R_j^2) / (m_i R_i^2 + m_j R_j^2)   (3-D, physics §2.2)
  // The batch carries m* = m_i m_j/(m_i + m_j), R_i and R_j, not m_i and m_j.
  // Assuming both spheres have the same density (true inside one domel
  // subdomain, whose particles share one material), m = c R^3 and
  //   m* = c R_i^3 R_j^3/(R_i^3 + R_j^3)  =>  c = m* (R_i^3 + R_j^3)/(R_i^3 R_j^3),
  //   I_r = 1.4 c R_i^5 R_j^5/(R_i^5 + R_j^5)
  //       = 1.4 m* (R_i^3 + R_j^3) R_i^2 R_j^2 / (R_i^5 + R_j^5).
  // Equal spheres: 1.4 m* R^2 = 0.7 m R^2, as the exact formula.
  // Wall: I_r = 1.4 m_i R_i^2 with m_i = m*.
  // The host's set-up probe of a particle pair (docs/sdk-guide.md) passes
  // R_j = 0 for two equal spheres with R* = R/2: I_r = 1.4 m* (2 R*)^2.
  static double rolling_inertia(const domel_contact_batch_v1& b, uint32_t c) {
    const double ri = b.radius_i[c], rj = b.radius_j[c];
    if (b.pair->is_wall != 0) return 1.4 * b.m_eff[c] * ri * ri;
    if (!(rj > 0.0)) return 1.4 * b.m_eff[c] * 4.0 * b.r_eff[c] * b.r_eff[c];
    const double ri2 = ri * ri, rj2 = rj * rj;
    const double ri3 = ri2 * ri, rj3 = rj2 * rj;
    return 1.4 * b.m_eff[c] * (ri3 + rj3) * ri2 * rj2 / (ri3 * ri2 + rj3 * rj2);
  }

  double mu_r_;
  double eta_r_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("third_party_rolling", "1.0.0", Epsd)
