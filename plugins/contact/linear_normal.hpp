// SPDX-License-Identifier: MIT
// Normal slot "linear": linear (Voigt / Cundall–Strack) spring, F_el = k_n delta
// (docs/physics.md §1.2). The stiffness is given directly, or derived per
// contact from a target contact duration t_c of the damped oscillator:
//   t_c = pi / sqrt(k/m* - eta^2/(4 m*^2)),  eta = 2 zeta sqrt(m* k),
//   zeta = -ln e / sqrt(pi^2 + ln^2 e)  =>  k = m* pi^2 / (t_c^2 (1 - zeta^2)).
// The contact radius reported to later stages is the geometric a = sqrt(R* delta).
// Coarse graining (docs/physics.md "Coarse-grain scaling"): in a subdomain
// with ratio alpha the given stiffness becomes alpha k_n, and a given contact
// time alpha t_c, so that a parcel at the same strain (delta ~ alpha) carries
// alpha^2 the force (the same contact stress) and its collision lasts alpha
// times longer, as a Hertz parcel does (LIGGGHTS-PFM doc/coarsegraining.txt:
// hooke/stiffness k_n -> alpha k_n; shared physics.md §4.2, §4.3). The
// restitution damping derived from k_n and m* then scales as alpha^2, the
// LIGGGHTS rule for gamma_n with damp_massflag 0.
#pragma once

#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace domel::plugins::contact {

class LinearNormal {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_NORMAL;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
  static constexpr const char* kName = "linear";
  static constexpr const char* kVersion = "1.1.0";
  static constexpr const char* kSummary =
      "linear spring k_n delta; k_n given or derived from a target contact time";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Linear normal spring. Give exactly one of stiffness or contact_time.",
  "properties": {
    "model": { "const": "linear" },
    "stiffness": { "type": "number", "exclusiveMinimum": 0, "x-unit": "N/m",
                   "description": "normal spring constant k_n of the original particles; a subdomain with coarse-grain ratio alpha uses alpha k_n" },
    "contact_time": { "type": "number", "exclusiveMinimum": 0, "x-unit": "s",
                      "description": "target duration of a binary collision of the original particles (alpha t_c for parcels of ratio alpha); k_n is derived per contact from m* and the restitution" }
  },
  "oneOf": [ { "required": ["stiffness"] }, { "required": ["contact_time"] } ],
  "additionalProperties": false
})json";

  explicit LinearNormal(const sdk::Params& p)
      : stiffness_(p.number_or("stiffness", 0.0)), contact_time_(p.number_or("contact_time", 0.0)) {
    if ((stiffness_ > 0.0) == (contact_time_ > 0.0))
      throw sdk::ParameterError("linear: give exactly one of 'stiffness' or 'contact_time'");
  }

  void compute(domel_contact_batch_v2& b) const {
    const double alpha = b.pair->coarse_grain > 0.0 ? b.pair->coarse_grain : 1.0;
    double factor = 0.0;  // k = factor * m* when derived from the contact time
    if (contact_time_ > 0.0) {
      const double le = std::log(b.pair->restitution);
      const double zeta2 = le * le / (M_PI * M_PI + le * le);
      const double tc = alpha * contact_time_;
      factor = M_PI * M_PI / (tc * tc * (1.0 - zeta2));
    }
    const double stiffness = alpha * stiffness_;
    for (uint32_t c = 0; c < b.n; ++c) {
      const double k = contact_time_ > 0.0 ? factor * b.m_eff[c] : stiffness;
      b.contact_radius[c] = std::sqrt(b.r_eff[c] * b.overlap[c]);
      b.kn[c] = k;
      b.kn_tangent[c] = k;
      b.fn_elastic[c] = k * b.overlap[c];
    }
  }

 private:
  double stiffness_;
  double contact_time_;
};

}  // namespace domel::plugins::contact
