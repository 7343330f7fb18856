// SPDX-License-Identifier: MIT
// Tangential slot "linear": linear tangential spring with history and
// Coulomb cap (Cundall & Strack 1979; docs/physics.md §1.2):
// k_t = stiffness_ratio * k_n, eta_t = damping_ratio * eta_n.
// Defaults: k_t/k_n = 2/7, which gives the tangential oscillation of a sphere
// the same frequency as the normal one (Schäfer, Dippel & Wolf 1996), and
// eta_t/eta_n = sqrt(k_t/k_n), i.e. eta_t = 2 zeta sqrt(m* k_t): the normal
// damping ratio zeta measured against m*. (Against the tangential mode's own
// effective mass (2/7) m* that is sqrt(7/2) = 1.87 times more damping.)
// History: 3 doubles (xi).
#pragma once

#include "tangential_kernel.hpp"

#include <domel/sdk/plugin.hpp>

namespace domel::plugins::contact {

class LinearTangential {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_TANGENTIAL;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
  static constexpr const char* kName = "linear";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary =
      "linear tangential spring k_t = ratio k_n with history and Coulomb cap";
  static constexpr unsigned kHistorySlots = 3;
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Linear tangential spring with Coulomb cap; friction from the material pair.",
  "properties": {
    "model": { "const": "linear" },
    "stiffness_ratio": { "type": "number", "exclusiveMinimum": 0, "default": 0.2857142857142857,
                         "x-unit": "1", "description": "k_t / k_n (default 2/7)" },
    "damping_ratio": { "type": "number", "minimum": 0, "x-unit": "1",
                       "description": "eta_t / eta_n (default sqrt(stiffness_ratio), i.e. eta_t = 2 zeta sqrt(m* k_t))" }
  },
  "additionalProperties": false
})json";

  explicit LinearTangential(const sdk::Params& p)
      : stiffness_ratio_(p.number_or("stiffness_ratio", 2.0 / 7.0)),
        damping_ratio_(p.number_or("damping_ratio", std::sqrt(stiffness_ratio_))) {}

  void compute(domel_contact_batch_v2& b) const {
    tangential_spring_coulomb<Dashpot::kScaled>(b, stiffness_ratio_, damping_ratio_, b.kn, b.eta_n);
  }

 private:
  double stiffness_ratio_;
  double damping_ratio_;
};

}  // namespace domel::plugins::contact
