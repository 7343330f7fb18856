// SPDX-License-Identifier: MIT
// output.repose_angle: every subdomain's angle of repose (the free-surface
// fit of subdomain/repose_probe.hpp) as <subdomain>.repose_angle_deg in
// probes.csv, and at the end in summary.json's "repose_angle_deg".
#pragma once

#include "loop/component.hpp"
#include "subdomain/repose_probe.hpp"

namespace domel::platform {

class ReposeAngleOutput final : public Component, public ProbeSource {
 public:
  explicit ReposeAngleOutput(ReposeProbeSettings settings) : settings_(std::move(settings)) {}
  unsigned points() const override { return 0; }
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  void probe_columns(std::vector<std::string>& names) const override;
  void probe_values(RunContext& ctx, double t, std::vector<double>& row) override;
  void set_subdomain_names(std::vector<std::string> names) { names_ = std::move(names); }

 private:
  ReposeProbeSettings settings_;
  std::vector<std::string> names_;  ///< the subdomains', in order
};

}  // namespace domel::platform
