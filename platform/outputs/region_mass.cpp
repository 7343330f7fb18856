// SPDX-License-Identifier: MIT
// output.region_mass (region_mass.hpp).
#include "outputs/region_mass.hpp"

#include "geometry/region.hpp"
#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <cmath>

namespace domel::platform {

namespace {

/// Kilograms and count of the particles inside the region, and (when com
/// is given) their centre of mass, from every subdomain's particles at t.
std::pair<double, std::size_t> mass_in_region(RunContext& ctx, double t, const RegionMassProbe& rm,
                                              double* com = nullptr) {
  double kg = 0;
  std::size_t n = 0;
  double mx = 0, my = 0, mz = 0;
  const double v2max = rm.max_speed ? *rm.max_speed * *rm.max_speed : 0.0;
  for (std::size_t d = 0; d < ctx.subdomains.size(); ++d) {
    if (rm.subdomain != kAllSubdomains && rm.subdomain != d) continue;
    const ParticleStore& s = ctx.particles(d, t);
    // the material's local index in this subdomain (none: it has no such particles)
    int local = -1;
    if (rm.material) {
      const auto& mats = ctx.subdomains[d]->materials();
      const auto it = std::find(mats.begin(), mats.end(), *rm.material);
      if (it == mats.end()) continue;
      local = static_cast<int>(it - mats.begin());
    }
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (local >= 0 && s.material[k] != local) continue;
      if (!region_contains(rm.region, s.x[k], s.y[k], s.z[k])) continue;
      if (rm.max_speed && s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k] + s.vz[k] * s.vz[k] >= v2max) continue;
      kg += s.mass[k];
      mx += s.mass[k] * s.x[k];
      my += s.mass[k] * s.y[k];
      mz += s.mass[k] * s.z[k];
      ++n;
    }
  }
  if (com) {
    com[0] = n ? mx / kg : std::nan("");
    com[1] = n ? my / kg : std::nan("");
    com[2] = n ? mz / kg : std::nan("");
  }
  return {kg, n};
}

}  // namespace

void RegionMassOutput::probe_columns(std::vector<std::string>& names) const {
  for (const auto& rm : probes_) {
    names.push_back(rm.name + ".mass_kg");
    names.push_back(rm.name + ".particles");
    if (rm.centre_of_mass)
      for (const char* c : {".com_x", ".com_y", ".com_z"}) names.push_back(rm.name + c);
  }
}

void RegionMassOutput::probe_values(RunContext& ctx, double t, std::vector<double>& row) {
  for (const auto& rm : probes_) {
    double com[3];
    const auto [kg, n] = mass_in_region(ctx, t, rm, com);
    row.push_back(kg);
    row.push_back(static_cast<double>(n));
    if (rm.centre_of_mass) row.insert(row.end(), com, com + 3);
  }
}

void RegionMassOutput::finish(RunContext& ctx, nlohmann::json& summary) {
  if (probes_.empty()) return;
  const double t = ctx.end_time;
  nlohmann::json rj = nlohmann::json::object();
  for (const auto& rm : probes_) {
    const auto [kg, n] = mass_in_region(ctx, t, rm);
    rj[rm.name] = {{"mass_kg", kg}, {"particles", n}};
  }
  summary["region_mass"] = rj;
}

}  // namespace domel::platform
