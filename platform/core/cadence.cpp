// SPDX-License-Identifier: MIT
// Cadence arithmetic (cadence.hpp says why due times are counted, not summed).
#include "core/cadence.hpp"

#include <algorithm>
#include <cmath>

namespace domel::platform {

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
  // on the first due time past t
  const double t = static_cast<double>(tick) * tick_;
  const double guess = std::floor((t + tolerance_ - first_) / period_);
  if (guess > static_cast<double>(k_) + 1 && guess < 9e15) k_ = static_cast<std::uint64_t>(guess) - 1;
  do {
    ++k_;
    next_ = first_ + static_cast<double>(k_) * period_;
  } while (next_ <= t + tolerance_);
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
