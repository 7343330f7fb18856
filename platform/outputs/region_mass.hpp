// SPDX-License-Identifier: MIT
// output.region_mass: the mass of the particles inside a region (a heap on
// a plate), as <name>.mass_kg and <name>.particles (and the centre of mass)
// in probes.csv, and at the end in summary.json's "region_mass".
#pragma once

#include "flow/particle_flow.hpp"
#include "loop/component.hpp"

#include <domel/sdk/abi.h>

#include <optional>
#include <string>
#include <vector>

namespace domel::platform {

struct RegionMassProbe {
  std::string name;
  std::size_t subdomain = kAllSubdomains;  ///< the only subdomain counted, or all
  domel_region_v1 region{};
  std::optional<double> max_speed;       ///< [m/s] only particles slower than this
  std::optional<std::size_t> material;   ///< only particles of this scenario material
  bool centre_of_mass = false;           ///< also <name>.com_x, .com_y, .com_z
};

class RegionMassOutput final : public Component, public ProbeSource {
 public:
  explicit RegionMassOutput(std::vector<RegionMassProbe> probes) : probes_(std::move(probes)) {}
  unsigned points() const override { return 0; }
  void finish(RunContext& ctx, nlohmann::json& summary) override;
  void probe_columns(std::vector<std::string>& names) const override;
  void probe_values(RunContext& ctx, double t, std::vector<double>& row) override;
  const std::vector<RegionMassProbe>& probes() const { return probes_; }

 private:
  std::vector<RegionMassProbe> probes_;
};

}  // namespace domel::platform
