// SPDX-License-Identifier: MIT
//
// The out-of-tree example plugin of tests/abi/out_of_tree: one normal-force
// model, "oot_linear" — a linear spring F = k delta — written with the SDK's
// C++ layer as a third party would, against the installed headers only.
#include <domel/sdk/plugin.hpp>

#include <cmath>

namespace {

class OotLinear {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_NORMAL;
  static constexpr const char* kName = "oot_linear";
  static constexpr const char* kVersion = "0.1.0";
  static constexpr const char* kSummary = "out-of-tree test model: linear spring k delta";
  static constexpr const char* kSchema = R"json({
  "type": "object",
  "properties": {
    "model": { "const": "oot_linear" },
    "stiffness": { "type": "number", "exclusiveMinimum": 0, "x-unit": "N/m",
                   "description": "spring constant k" }
  },
  "required": ["stiffness"],
  "additionalProperties": false
})json";

  explicit OotLinear(const domel::sdk::Params& p) : k_(p.number("stiffness")) {
    if (!(k_ > 0.0)) throw domel::sdk::ParameterError("oot_linear: 'stiffness' must be positive");
  }

  void compute(domel_contact_batch_v2& b) const {
    for (uint32_t c = 0; c < b.n; ++c) {
      b.fn_elastic[c] = k_ * b.overlap[c];
      b.kn[c] = k_;
      b.kn_tangent[c] = k_;
      b.contact_radius[c] = std::sqrt(b.r_eff[c] * b.overlap[c]);
    }
  }

 private:
  double k_;
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("my_plugin", "0.1.0", OotLinear)
