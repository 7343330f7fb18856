// SPDX-License-Identifier: MIT
// Tangential slot "mindlin": Mindlin no-slip tangential spring with history
// and Coulomb cap (Mindlin 1949; LIGGGHTS tangential_model_history,
// docs/physics.md §1.1): k_t = 8 G* a with the contact radius a from the
// normal stage, eta_t = 2 sqrt(5/6) |beta| sqrt(k_t m*) from the pair's
// restitution (set "damping": false to drop it). History: 3 doubles (xi).
#pragma once

#include "tangential_kernel.hpp"

#include <domel/sdk/plugin.hpp>

namespace domel::plugins::contact {

class Mindlin {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_TANGENTIAL;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
  static constexpr const char* kName = "mindlin";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary =
      "Mindlin tangential spring 8 G* a with history, dashpot while sticking, Coulomb cap mu|F_n|";
  static constexpr unsigned kHistorySlots = 3;
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Mindlin no-slip tangential spring with Coulomb cap; friction from the material pair.",
  "properties": {
    "model": { "const": "mindlin" },
    "damping": { "type": "boolean", "default": true,
                 "description": "add the tangential dashpot 2 sqrt(5/6)|beta| sqrt(k_t m*) while sticking" }
  },
  "additionalProperties": false
})json";

  explicit Mindlin(const sdk::Params& p) : damping_(p.boolean_or("damping", true)) {}

  void compute(domel_contact_batch_v2& b) const {
    const double g_eff = b.pair->shear_eff;
    const double le = std::log(b.pair->restitution);
    const double c_damp =
        damping_ ? 2.0 * std::sqrt(5.0 / 6.0) * std::fabs(le) / std::sqrt(le * le + M_PI * M_PI) : 0.0;
    tangential_spring_coulomb<Dashpot::kSqrtMass>(b, 8.0 * g_eff, c_damp, b.contact_radius, b.m_eff);
  }

 private:
  bool damping_;
};

}  // namespace domel::plugins::contact
