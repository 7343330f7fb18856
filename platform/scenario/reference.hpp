// SPDX-License-Identifier: MIT
// Human-readable renderings of schemas: the parameter table of one model
// (for `domel plugins`) and the Markdown scenario reference (for
// `domel docs`, committed as docs/scenario-reference.md). Both are produced
// from the same schemas the validator uses, so they cannot drift.
#pragma once

#include "loader/plugin_registry.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace domel::platform {

struct ParameterRow {
  std::string name, type, unit, default_value, constraint, description;
  bool required = false;
};

/// One row per property of an object schema (platform-owned "model" key skipped).
std::vector<ParameterRow> parameter_rows(const nlohmann::json& object_schema, const nlohmann::json& root);

/// The scenario reference in Markdown: every platform block and every registered model.
std::string scenario_reference_markdown(const PluginRegistry& registry);

}  // namespace domel::platform
