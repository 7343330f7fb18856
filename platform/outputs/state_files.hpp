// SPDX-License-Identifier: MIT
// output.state: at the end of the run, <subdomain>_state.csv for every
// subdomain, all its particles at full precision (io/particle_state.hpp),
// to start later runs from (subdomains[k].initial_state).
#pragma once

#include "loop/component.hpp"

#include <string>
#include <vector>

namespace domel::platform {

class StateFiles final : public Component {
 public:
  /// `materials`: the scenario's material names.
  explicit StateFiles(std::vector<std::string> materials) : materials_(std::move(materials)) {}
  unsigned points() const override { return 0; }
  void finish(RunContext& ctx, nlohmann::json& summary) override;

 private:
  std::vector<std::string> materials_;
};

}  // namespace domel::platform
