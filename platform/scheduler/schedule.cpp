// SPDX-License-Identifier: MIT
// Interval arithmetic (schedule.hpp says why due times are counted, not summed).
#include "scheduler/schedule.hpp"

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

Interval::Interval(double period, double first, double macro_step)
    : period_(period), first_(first), tolerance_(kTimeTolerance * macro_step) {
  if (period_ > 0) next_ = first_;
}

void Interval::advance(double t) {
  if (period_ <= 0) return;
  // jump close to t in one go (a period far below the macro step would
  // otherwise loop many times), then settle on the first due time past t
  const double guess = std::floor((t + tolerance_ - first_) / period_);
  if (guess > static_cast<double>(k_) + 1 && guess < 9e15) k_ = static_cast<std::uint64_t>(guess) - 1;
  do {
    ++k_;
    next_ = first_ + static_cast<double>(k_) * period_;
  } while (next_ <= t + tolerance_);
}

}  // namespace domel::platform
