// SPDX-License-Identifier: MIT
//
// Rolling slot "epsd": the elastic-plastic spring-dashpot rolling resistance
// of Ai, Chen, Rotter & Ooi (2011), "Assessment of rolling resistance models
// in discrete element simulations", Powder Technol. 206, 269-282 ("model C"),
// as LIGGGHTS computes it (rolling_model_epsd.h; docs/physics.md, rolling
// models, and docs/tutorial-rolling-plugin.md). A third-party plugin: it is built
// against the INSTALLED domel SDK only (see CMakeLists.txt, README.md and
// docs/tutorial-rolling-plugin.md, whose code is this file).
//
// Per contact and time step, with omega_r the rolling part of the relative
// angular velocity omega_i - omega_j:
//   k_r   = 2.25 k_n mu_r^2 R*^2          rolling spring, "stiffness": "ai"
//                                         (Jiang et al. 2005's contact width,
//                                         via Ai et al. 2011; LIGGGHTS epsd)
//   k_r   = k_t R*^2                      "stiffness": "iwashita_oda"
//                                         (Iwashita & Oda 1998; LIGGGHTS epsd2)
//   M_k  += k_r omega_r dt                spring torque, kept in the history
//   M_max = mu_r R* F_n                   plastic limit
//   |M_k| > M_max:  M_k <- M_k M_max/|M_k|, stored; M = M_k   (no dashpot: Ai's f = 0)
//   otherwise:      M = M_k + C_r omega_r,  C_r = eta_r 2 sqrt(I_r k_r)
//                   ("dashpot": false: M = M_k, as LIGGGHTS epsd2 after
//                   Wensrich & Katterfeld 2012)
//   torque on i: -M (the host gives j +M)
// LIGGGHTS epsd is {"stiffness": "ai", "dashpot": true} (the defaults) and
// epsd2 is {"stiffness": "iwashita_oda", "dashpot": false}.
// Choices where the batch or the sources leave room (all documented in the
// tutorial):
//  - k_n is the normal model's secant stiffness `kn` = F_el/delta, which is
//    what LIGGGHTS hands the rolling model (cdata.kn, 4/3 E* sqrt(R* delta)
//    for Hertz).
//  - k_t is the Mindlin tangential stiffness 8 G* a (physics.md §1.1), with a the contact
//    radius the normal stage writes (sqrt(R* delta) for Hertz) and G* the
//    pair's shear_eff: what domel's `mindlin` stage uses and LIGGGHTS hands
//    epsd2 (cdata.kt, 8 G* sqrt(R* delta)). The batch does not carry the
//    tangential stage's stiffness, so it is recomputed here; with another
//    tangential model it is still 8 G* a.
//  - F_n is the total normal force `fn` (elastic + dashpot) that the host sums
//    before the tangential stage, as LIGGGHTS's cdata.Fn; a net attractive
//    value counts as 0 (LIGGGHTS with limitForce).
//  - The stored M_k is rotated into the current tangent plane (projected, its
//    length kept: domel::sdk::tangent_keep_length) before the increment, so
//    that it never acquires a twisting component. LIGGGHTS stores it
//    unrotated.
//  - mu_r is the material pair's rolling friction when the scenario sets one
//    for the pair (domel_pair_v2::has_rolling_friction), else the model's
//    "rolling_friction" parameter.
//  - I_r from the two particles' masses and radii (mass_i, mass_j of the
//    batch, ABI 2): see rolling_inertia() below.
// History: 3 doubles, the spring torque M_k [N m].
#include <domel/sdk/kinematics.hpp>
#include <domel/sdk/plugin.hpp>

#include <cmath>
#include <sstream>
#include <string>

namespace {

class Epsd {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr const char* kName = "epsd";
  static constexpr const char* kVersion = "1.1.0";
  static constexpr const char* kSummary =
      "elastic-plastic spring-dashpot rolling resistance (Ai et al. 2011 model C, as LIGGGHTS epsd and epsd2)";
  static constexpr unsigned kHistorySlots = 3;  // M_k, the spring torque vector
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Elastic-plastic spring-dashpot (EPSD) rolling resistance of Ai et al. (2011), model C: an incremental rolling spring k_r capped at mu_r R* F_n, plus a dashpot while the spring is below the cap. LIGGGHTS epsd: the defaults; LIGGGHTS epsd2: stiffness iwashita_oda, dashpot false.",
  "properties": {
    "rolling_friction": { "type": "number", "minimum": 0, "x-unit": "1",
                          "description": "coefficient of rolling friction mu_r: the torque cap is mu_r R* F_n" },
    "stiffness": { "enum": ["ai", "iwashita_oda"], "default": "ai",
                   "description": "rolling spring k_r: ai = 2.25 k_n mu_r^2 R*^2 (Ai et al. 2011, LIGGGHTS epsd; k_n the secant normal stiffness); iwashita_oda = k_t R*^2 (Iwashita & Oda 1998, LIGGGHTS epsd2; k_t = 8 G* a the Mindlin tangential stiffness)" },
    "dashpot": { "type": "boolean", "default": true,
                 "description": "add the rolling dashpot C_r omega_r while the spring is below the cap (LIGGGHTS epsd); false: no viscous torque at all (LIGGGHTS epsd2, Wensrich & Katterfeld 2012)" },
    "viscous_damping": { "type": "number", "minimum": 0, "default": 0, "x-unit": "1",
                         "description": "rolling viscous damping ratio eta_r: C_r = eta_r 2 sqrt(I_r k_r); only with dashpot true" }
  },
  "required": ["rolling_friction"],
  "additionalProperties": false
})json";

  explicit Epsd(const domel::sdk::Params& p)
      : mu_r_(p.number("rolling_friction")),
        eta_r_(p.number_or("viscous_damping", 0.0)),
        iwashita_oda_(iwashita_oda(p)),
        dashpot_(p.boolean_or("dashpot", true)) {
    // The schema already says all this; the constructor also refuses NaN and
    // guards a host that did not validate.
    if (!(mu_r_ >= 0.0))
      throw domel::sdk::ParameterError("epsd: 'rolling_friction' must be a number >= 0");
    if (!(eta_r_ >= 0.0))
      throw domel::sdk::ParameterError("epsd: 'viscous_damping' must be a number >= 0");
    if (!dashpot_ && eta_r_ > 0.0) {
      std::ostringstream what;
      what << "epsd: 'viscous_damping' is " << eta_r_
           << " but 'dashpot' is false, which means no viscous torque; drop one of the two";
      throw domel::sdk::ParameterError(what.str());
    }
  }

  // Called from several threads at once on the same instance (abi.h):
  // const, and every per-contact state lives in b.history. The SDK hands
  // compute() batches of one material pair (b.pair is set).
  void compute(domel_contact_batch_v2& b) const {
    using domel::sdk::Vec3;
    const uint32_t stride = b.history_stride;
    const double mu_r = b.pair->has_rolling_friction != 0 ? b.pair->rolling_friction : mu_r_;
    const bool wall = b.pair->is_wall != 0;
    for (uint32_t c = 0; c < b.n; ++c) {
      const double nx = b.nx[c], ny = b.ny[c], nz = b.nz[c];

      // omega_r: the rolling part of omega_i - omega_j (the part about n is twisting).
      const Vec3 wr = domel::sdk::rolling_velocity(b.wx[c], b.wy[c], b.wz[c], nx, ny, nz);

      // Spring, dashpot and cap of this contact.
      const double r = b.r_eff[c];
      const double k_r = iwashita_oda_ ? 8.0 * b.pair->shear_eff * b.contact_radius[c] * r * r
                                       : 2.25 * b.kn[c] * mu_r * mu_r * r * r;
      const double c_r = dashpot_ ? eta_r_ * 2.0 * std::sqrt(rolling_inertia(b, c, wall) * k_r) : 0.0;
      const double m_max = mu_r * r * domel::sdk::cap_force(b.fn[c]);

      // M_k from the history, carried into the current tangent plane (its length kept).
      double* h = b.history + static_cast<size_t>(c) * stride;
      const Vec3 mk = domel::sdk::tangent_keep_length(h[0], h[1], h[2], nx, ny, nz);

      // Incremental spring: M_k += k_r omega_r dt.
      double mx = mk.x + k_r * wr.x * b.dt, my = mk.y + k_r * wr.y * b.dt, mz = mk.z + k_r * wr.z * b.dt;

      // Plastic cap, or the dashpot while elastic.
      const double len = std::sqrt(mx * mx + my * my + mz * mz);
      double tx, ty, tz;  // M, the resisting moment before the sign
      if (len > m_max) {
        const double scale = m_max / len;  // len > m_max >= 0
        mx *= scale; my *= scale; mz *= scale;
        tx = mx; ty = my; tz = mz;  // fully mobilised: no dashpot (Ai et al.'s f = 0)
      } else {
        tx = mx + c_r * wr.x; ty = my + c_r * wr.y; tz = mz + c_r * wr.z;
      }
      h[0] = mx; h[1] = my; h[2] = mz;

      // The couple on i is -M, added to what earlier stages wrote; j gets +M from the host.
      b.tqx[c] -= tx; b.tqy[c] -= ty; b.tqz[c] -= tz;

      // For the host's rotational time-step check.
      b.rolling_stiffness[c] = k_r;
      b.rolling_damping[c] = c_r;
    }
  }

 private:
  // "stiffness": true for "iwashita_oda", false for "ai" (the default);
  // anything else is refused.
  static bool iwashita_oda(const domel::sdk::Params& p) {
    const std::string stiffness = p.string_or("stiffness", "ai");
    if (stiffness != "ai" && stiffness != "iwashita_oda")
      throw domel::sdk::ParameterError("epsd: 'stiffness' must be \"ai\" or \"iwashita_oda\", found \"" + stiffness +
                                       "\"");
    return stiffness == "iwashita_oda";
  }

  // I_r = 1.4 (m_i R_i^2)(m_j R_j^2) / (m_i R_i^2 + m_j R_j^2)   (3-D, physics §2.2),
  // from the batch's masses and radii; a wall (mass_j = 0): I_r = 1.4 m_i R_i^2.
  // Equal spheres: 0.7 m R^2.
  static double rolling_inertia(const domel_contact_batch_v2& b, uint32_t c, bool wall) {
    const double ii = b.mass_i[c] * b.radius_i[c] * b.radius_i[c];
    if (wall || !(b.mass_j[c] > 0.0)) return 1.4 * ii;
    const double ij = b.mass_j[c] * b.radius_j[c] * b.radius_j[c];
    return 1.4 * ii * ij / (ii + ij);
  }

  double mu_r_;
  double eta_r_;
  bool iwashita_oda_;  // k_r = k_t R*^2, else 2.25 k_n mu_r^2 R*^2
  bool dashpot_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("third_party_rolling", "1.1.0", Epsd)
