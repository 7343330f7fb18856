// SPDX-License-Identifier: MIT
// output.repose_angle (repose_angle.hpp).
#include "outputs/repose_angle.hpp"

#include <cmath>

namespace domel::platform {

void ReposeAngleOutput::probe_columns(std::vector<std::string>& names) const {
  for (const auto& n : names_) names.push_back(n + ".repose_angle_deg");
}

void ReposeAngleOutput::probe_values(RunContext& ctx, double t, std::vector<double>& row) {
  for (std::size_t k = 0; k < ctx.subdomains.size(); ++k)
    row.push_back(repose_angle(ctx.particles(k, t), settings_).value_or(std::nan("")));
}

void ReposeAngleOutput::finish(RunContext& ctx, nlohmann::json& summary) {
  nlohmann::json angles = nlohmann::json::object();
  for (std::size_t k = 0; k < ctx.subdomains.size(); ++k) {
    const auto a = repose_angle(ctx.particles(k, ctx.end_time), settings_);
    angles[names_[k]] = a ? nlohmann::json(*a) : nlohmann::json(nullptr);
  }
  summary["repose_angle_deg"] = angles;
}

}  // namespace domel::platform
