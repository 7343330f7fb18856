// SPDX-License-Identifier: MIT
// The macro step of a set of subdomains (macro_step.hpp).
#include "loop/macro_step.hpp"

#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <cmath>

namespace domel::platform {

double macro_step_of(const std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  double dt = 0;
  for (const auto& sd : subdomains) dt = std::max(dt, sd->time_step());
  return dt;
}

int substeps_of(double macro, double dt) {
  return std::max(1, static_cast<int>(std::ceil(macro / dt - kTimeTolerance)));
}

}  // namespace domel::platform
