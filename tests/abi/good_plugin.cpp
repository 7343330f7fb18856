// SPDX-License-Identifier: MIT
//
// A valid minimal plugin for the ABI tests, written with the C++ layer: one
// rolling-resistance model, "abi_good_rolling" (constant directional torque
// -mu_r R* F_n w/|w|). Its constructor refuses a missing, non-numeric or
// non-positive "coefficient" with its own message, which the tests expect to see inside
// the host's PluginError. It is also the "first library" of the duplicate
// test and the good half of the load_directory test.
#include <domel/sdk/plugin.hpp>

#include <cmath>
#include <string>

namespace {

class GoodRolling {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr const char* kName = "abi_good_rolling";
  static constexpr const char* kVersion = "1.2.3";
  static constexpr const char* kSummary = "ABI test model: constant directional rolling torque";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "properties": {
    "model": { "const": "abi_good_rolling" },
    "coefficient": { "type": "number", "exclusiveMinimum": 0, "x-unit": "1",
                     "description": "rolling-friction coefficient mu_r" }
  },
  "required": ["coefficient"],
  "additionalProperties": false
})json";

  explicit GoodRolling(const domel::sdk::Params& p) : mu_r_(0.0) {
    if (!p.has("coefficient")) throw domel::sdk::ParameterError("abi_good_rolling needs a 'coefficient'");
    mu_r_ = p.number("coefficient");
    if (!(mu_r_ > 0.0))
      throw domel::sdk::ParameterError("abi_good_rolling wants a positive 'coefficient', got " +
                                       std::to_string(mu_r_));
  }

  void compute(domel_contact_batch_v2& b) const {
    for (uint32_t c = 0; c < b.n; ++c) {
      const double w = std::sqrt(b.wx[c] * b.wx[c] + b.wy[c] * b.wy[c] + b.wz[c] * b.wz[c]);
      if (w == 0.0) continue;
      const double s = -mu_r_ * b.r_eff[c] * b.fn[c] / w;
      b.tqx[c] += s * b.wx[c];
      b.tqy[c] += s * b.wy[c];
      b.tqz[c] += s * b.wz[c];
    }
  }

 private:
  double mu_r_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("abi_good", "1.0.0", GoodRolling)
