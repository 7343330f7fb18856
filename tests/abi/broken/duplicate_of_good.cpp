// SPDX-License-Identifier: MIT
//
// Broken plugin (case g, first half), written with the C++ layer: it offers
// a harmless unique damping model and then a rolling model named
// "abi_good_rolling" — the same (kind, name) as good_plugin.cpp. Loaded after
// the good plugin it must be refused as a duplicate naming the good plugin's
// file, and its unique model must not be registered either.
#include <domel/sdk/plugin.hpp>

namespace {

class UniqueDamping {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_DAMPING;
  static constexpr const char* kName = "duplicate_of_good_unique";
  static constexpr const char* kVersion = "1.0.0";
  static constexpr const char* kSummary = "would be fine on its own";
  static constexpr const char* kSchema = R"json({"type": "object"})json";
  explicit UniqueDamping(const domel::sdk::Params&) {}
  void compute(domel_contact_batch_v2&) const {}
};

class SameNameRolling {
 public:
  static constexpr domel_kind kKind = DOMEL_KIND_ROLLING;
  static constexpr const char* kName = "abi_good_rolling";
  static constexpr const char* kVersion = "9.9.9";
  static constexpr const char* kSummary = "clashes with the good plugin";
  static constexpr const char* kSchema = R"json({"type": "object"})json";
  explicit SameNameRolling(const domel::sdk::Params&) {}
  void compute(domel_contact_batch_v2&) const {}
};

}  // namespace

DOMEL_PLUGIN_LIBRARY("duplicate_of_good", "1.0.0", UniqueDamping, SameNameRolling)
