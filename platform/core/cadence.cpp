// SPDX-License-Identifier: MIT
// Cadence arithmetic (cadence.hpp says why due times are counted, not summed).
#include "core/cadence.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace domel::platform {

std::string schedule_refusal(double period, double tick, const std::string& what) {
  if (!(period > 0) || !(tick > 0) || period >= tick * (1.0 - kTimeTolerance)) return {};
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "expected at least the macro step, %.6g s (the largest subdomain time step: %s are due at macro "
                "steps, at most one per step), or 0 to switch them off; found %.6g s",
                tick, what.c_str(), period);
  return buf;
}

Cadence Cadence::in_time(double period, double first, double tick) {
  Cadence c;
  if (!(period > 0) || !(tick > 0)) return c;
  c.enabled_ = true;
  c.period_ = period;
  c.first_ = first;
  c.tick_ = tick;
  c.tolerance_ = kTimeTolerance * tick;
  c.settle();
  return c;
}

Cadence Cadence::in_ticks(std::uint64_t n, std::uint64_t first) {
  Cadence c;
  if (n == 0) return c;
  c.enabled_ = true;
  c.every_ = n;
  c.first_tick_ = first;
  c.settle();
  return c;
}

void Cadence::settle() {
  if (!enabled_) return;
  if (every_ > 0) {
    const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
    next_tick_ = k_ > (max - first_tick_) / every_ ? max : first_tick_ + k_ * every_;
    return;
  }
  next_ = first_ + static_cast<double>(k_) * period_;
  // the first tick m with m x tick >= next - tolerance, by the very
  // comparison a time m x tick is later tested with
  const double reach = next_ - tolerance_;
  const double guess = std::ceil(reach / tick_);
  if (!(guess < 1.8e19)) {
    next_tick_ = std::numeric_limits<std::uint64_t>::max();
    return;
  }
  std::uint64_t m = guess > 0 ? static_cast<std::uint64_t>(guess) : 0;
  while (m > 0 && static_cast<double>(m - 1) * tick_ >= reach) --m;
  while (static_cast<double>(m) * tick_ < reach) ++m;
  next_tick_ = m;
}

void Cadence::advance(std::uint64_t tick) {
  if (!enabled_) return;
  if (every_ > 0) {
    if (tick >= first_tick_) k_ = std::max(k_, (tick - first_tick_) / every_ + 1);
    settle();
    return;
  }
  // every due time reached by tick's time t: jump close to t in one go (a
  // period far below the tick would otherwise loop many times), then settle
  // on the first due time past t, a few periods on at most. A period below
  // what the times resolve (first + k x period no longer grows with k, or k
  // beyond 2^64) leaves the next due time reached: due at every tick, as
  // any period below the tick is, and never a loop without end.
  const double t = static_cast<double>(tick) * tick_;
  const double guess = std::floor((t + tolerance_ - first_) / period_);
  constexpr double kIndexLimit = 1.8e19;  // below 2^64
  if (guess > static_cast<double>(k_) + 1) k_ = guess < kIndexLimit ? static_cast<std::uint64_t>(guess) - 1 : k_;
  for (int left = 64; left > 0; --left) {
    const double before = next_;
    if (k_ == std::numeric_limits<std::uint64_t>::max()) break;
    ++k_;
    next_ = first_ + static_cast<double>(k_) * period_;
    if (next_ > t + tolerance_ || !(next_ > before)) break;
  }
  settle();
}

void Cadence::resume(std::uint64_t k) {
  k_ = k;
  settle();
}

void Cadence::restore(std::uint64_t k, double period_then, std::uint64_t at) {
  if (period_then == period_) resume(k);
  else if (at > 0) advance(at - 1);
}

}  // namespace domel::platform
