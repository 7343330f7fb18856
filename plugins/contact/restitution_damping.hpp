// SPDX-License-Identifier: MIT
// Damping slot "restitution": normal dashpot chosen so that a binary collision
// rebounds with the material pair's coefficient of restitution e.
//   beta = ln e / sqrt(ln^2 e + pi^2)   (|beta| is the damping ratio zeta)
//   linear spring (F ~ delta):   eta_n = 2 |beta| sqrt(m* k_n)            — exact (physics.md §1.2)
//   Hertz (F ~ delta^{3/2}):     eta_n = 2 sqrt(5/6) |beta| sqrt(m* S_n)  — Tsuji et al. 1992 closed form
//                                 as used by LIGGGHTS (physics.md §1.1), S_n the tangent stiffness.
// Which form applies is read from the normal stage's output: for a power law
// F = c delta^p the ratio tangent/secant stiffness equals p exactly, so p = 1
// selects the linear form and p = 3/2 the Hertz form; any other normal law is
// refused with a message (add a damping model for it).
#pragma once

#include <domel/sdk/plugin.hpp>

#include <cmath>
#include <string>

namespace domel::plugins::contact {

class RestitutionDamping {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_DAMPING;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
  static constexpr const char* kName = "restitution";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary =
      "normal dashpot from the pair's coefficient of restitution (linear and Hertz springs)";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Normal damping from the material pair's restitution coefficient.",
  "properties": { "model": { "const": "restitution" } },
  "additionalProperties": false
})json";

  explicit RestitutionDamping(const sdk::Params&) {}

  void compute(domel_contact_batch_v2& b) const {
    if (b.n == 0) return;
    const double e = b.pair->restitution;
    const double le = std::log(e);
    const double abs_beta = std::fabs(le) / std::sqrt(le * le + M_PI * M_PI);
    const double p = b.kn_tangent[0] / b.kn[0];
    double prefactor;
    if (std::fabs(p - 1.0) < 1e-6) {
      prefactor = 2.0 * abs_beta;
    } else if (std::fabs(p - 1.5) < 1e-6) {
      prefactor = 2.0 * std::sqrt(5.0 / 6.0) * abs_beta;
    } else {
      throw std::runtime_error("restitution damping supports linear (p = 1) and Hertz (p = 1.5) normal laws; "
                               "the normal model gives p = " + std::to_string(p));
    }
    for (uint32_t c = 0; c < b.n; ++c) {
      const double eta = prefactor * std::sqrt(b.m_eff[c] * b.kn_tangent[c]);
      b.eta_n[c] = eta;
      b.fn_damping[c] = eta * b.vn[c];
    }
  }
};

}  // namespace domel::plugins::contact
