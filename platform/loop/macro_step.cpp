// SPDX-License-Identifier: MIT
// The macro step of a set of subdomains (macro_step.hpp).
#include "loop/macro_step.hpp"

#include "subdomain/subdomain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace domel::platform {

double macro_step_of(const std::vector<std::unique_ptr<Subdomain>>& subdomains) {
  double dt = 0;
  for (const auto& sd : subdomains) dt = std::max(dt, sd->time_step());
  return dt;
}

int substeps_of(double macro, double dt) {
  // bounded before the conversion: levels whose steps differ by more than an
  // int counts (1000 s against 2e-7 s; the run-time fuzzer gave levels such
  // steps) get the most one holds
  const double n = std::ceil(macro / dt - kTimeTolerance);
  if (!(n >= 1.0)) return 1;  // NaN too
  if (n >= static_cast<double>(std::numeric_limits<int>::max())) return std::numeric_limits<int>::max();
  return static_cast<int>(n);
}

}  // namespace domel::platform
