// SPDX-License-Identifier: MIT
// Normal slot "hertz": elastic Hertz contact between spheres.
// F_el = (4/3) E* sqrt(R*) delta^{3/2}; secant stiffness k_n = (4/3) E* a,
// tangent stiffness S_n = 2 E* a, contact radius a = sqrt(R* delta)
// (Hertz 1882; as in LIGGGHTS normal_model_hertz — docs/physics.md §1.1).
// E* comes from the material pair. No parameters, no history.
#pragma once

#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace domel::plugins::contact {

class Hertz {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_NORMAL;
  static constexpr bool kReadsMasses = false;  // abi.h: DOMEL_CONTACT_IGNORES_MASSES
  static constexpr const char* kName = "hertz";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary =
      "Hertz elastic normal force (4/3) E* sqrt(R*) delta^1.5 from the materials' E and nu";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "description": "Hertz normal contact; stiffness follows from the materials' youngs_modulus and poisson_ratio.",
  "properties": { "model": { "const": "hertz" } },
  "additionalProperties": false
})json";

  explicit Hertz(const sdk::Params&) {}

  void compute(domel_contact_batch_v2& b) const {
    kernel(b.n, b.pair->youngs_eff, b.r_eff, b.overlap, b.contact_radius, b.kn, b.kn_tangent, b.fn_elastic);
  }

 private:
  // __restrict parameters (GCC ignores restrict on local pointers): the loop vectorises.
  static void kernel(uint32_t n, double e_eff, const double* __restrict r_eff, const double* __restrict overlap,
                     double* __restrict radius, double* __restrict kn, double* __restrict kn_tangent,
                     double* __restrict fn_elastic) {
    for (uint32_t c = 0; c < n; ++c) {
      const double a = std::sqrt(r_eff[c] * overlap[c]);
      const double k = (4.0 / 3.0) * e_eff * a;
      radius[c] = a;
      kn[c] = k;
      kn_tangent[c] = 1.5 * k;  // dF/d delta = 2 E* a
      fn_elastic[c] = k * overlap[c];
    }
  }
};

}  // namespace domel::plugins::contact
