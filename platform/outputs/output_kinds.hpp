// SPDX-License-Identifier: MIT
// Output kinds registered by name: a block of the scenario's `output`, its
// JSON Schema and the function that makes its run component
// (loop/component.hpp). A new output is one Component class, one schema
// block and one registration line beside it:
//
//   const OutputKindRegistration kMine{{"mine", kMineSchema, make_mine}};
//
// The schema joins the scenario schema's output block, so a scenario's block
// is validated, its defaults filled, and `domel schema` and `domel docs`
// show it; a scenario that has the block gets the component, registered
// after the built-in outputs (scenario/builders.cpp). The registration must
// run before the first scenario is read (a namespace-scope object in the
// executable or in an object file it links whole; a static library drops an
// object file nothing refers to).
#pragma once

#include "loop/component.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

/// What an output kind's factory sees of the scenario.
struct OutputSetting {
  const nlohmann::json& block;          ///< output.<key>, its defaults filled, valid by its schema
  std::string pointer;                  ///< "/output/<key>", for messages
  std::vector<std::string> subdomains;  ///< the subdomains' names, in order
  std::vector<std::string> materials;   ///< the scenario's material names, in order
  double duration = 0;                  ///< [s] the run's
  double macro = 0;                     ///< [s] the macro step
};

/// Makes the component; throws ConfigError (with setting.pointer) for a
/// block its schema cannot refuse (a subdomain that does not exist).
using OutputFactory = std::function<std::unique_ptr<Component>(const OutputSetting&)>;

struct OutputKind {
  std::string key;        ///< output.<key>
  nlohmann::json schema;  ///< the block's JSON Schema
  OutputFactory make;
};

/// Every registered kind, in registration order.
const std::vector<OutputKind>& output_kinds();

struct OutputKindRegistration {
  explicit OutputKindRegistration(OutputKind kind);
};

}  // namespace domel::platform
