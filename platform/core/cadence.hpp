// SPDX-License-Identifier: MIT
// The run's one notion of "every so often": a Cadence, resolved once into
// the ticks of a clock (the macro steps of a run, or the steps of one
// subdomain), owned by the component that acts on it. Every periodic action
// of a run uses one: VTK frames, probe rows, contact frames, grid files and
// samples, pour events, deletion and mass-flow plane checks, checkpoints,
// the couplings' control interval, the fluid exchange and its field files.
//
// A cadence in simulated time (in_time) is due at the ticks that reach
// first + k * period: due times are computed from k rather than summed, so
// round-off does not accumulate over a long run, and tick m (at time
// m x tick) counts as having reached a due time d when m x tick >= d -
// kTimeTolerance x tick (a multiple of the tick that round-off leaves a
// hair short of a due time exactly on it). Several due times within one
// tick fire once. A cadence in ticks (in_ticks) is due at first, first + n,
// first + 2n, ... exactly.
//
// Stateful use (take/advance): a component asks at every tick whether its
// action is due and marks it done; the index of the next due time goes into
// checkpoints (resume). Stateless use (on): whether a tick is one of a
// tick cadence's due ticks, for clocks that are not followed tick by tick.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace domel::platform {

/// Fraction of the macro step by which a time may fall short of a due time
/// and still count as having reached it.
inline constexpr double kTimeTolerance = 1e-9;

/// Why an interval of `period` seconds cannot be kept on a clock whose
/// ticks are `tick` seconds apart (the macro step): below one tick, where
/// at most one action per tick is due; empty when it can (0, off, can).
/// `what` names the actions ("particle files"). The scenario's schedules
/// are checked with it at validate (scenario/build_schedules.cpp); an output
/// kind with an interval of its own checks it the same way.
std::string schedule_refusal(double period, double tick, const std::string& what);

class Cadence {
 public:
  /// Never due.
  Cadence() = default;
  /// Every `period` seconds from `first` on a clock whose ticks are `tick`
  /// seconds apart (the macro step); period <= 0: never due.
  static Cadence in_time(double period, double first, double tick);
  /// Every `n` ticks from tick `first`; n = 0: never due.
  static Cadence in_ticks(std::uint64_t n, std::uint64_t first = 0);

  bool enabled() const { return enabled_; }
  /// Tick `tick` has reached the next due time.
  bool due(std::uint64_t tick) const { return enabled_ && tick >= next_tick_; }
  /// Mark every due time that tick `tick` has reached as done.
  void advance(std::uint64_t tick);
  /// due(tick), and if so advance(tick): "is it time, and mark it done".
  bool take(std::uint64_t tick) {
    if (!due(tick)) return false;
    advance(tick);
    return true;
  }
  /// Whether `tick` is a due tick of a cadence in ticks (no state involved).
  bool on(std::uint64_t tick) const {
    return enabled_ && every_ > 0 && tick >= first_tick_ && (tick - first_tick_) % every_ == 0;
  }

  /// Index of the next due time; checkpoints keep it.
  std::uint64_t index() const { return k_; }
  void resume(std::uint64_t k);
  /// A restart: go on from index k when the cadence is the one that
  /// counted it (the same period), else from the first due time after tick
  /// `at` - 1 (the last tick the checkpointed run had acted at; none at 0).
  void restore(std::uint64_t k, double period_then, std::uint64_t at);

  /// [s] for a cadence in time, 0 otherwise.
  double period() const { return period_; }
  /// Ticks between due ticks of a cadence in ticks, 0 otherwise.
  std::uint64_t every() const { return every_; }
  /// The next due time [s] of a cadence in time.
  double next_time() const { return next_; }

 private:
  void settle();  ///< next_ and next_tick_ from k_

  bool enabled_ = false;
  // in time
  double period_ = 0, first_ = 0, tick_ = 0, tolerance_ = 0;
  double next_ = std::numeric_limits<double>::infinity();
  // in ticks
  std::uint64_t every_ = 0, first_tick_ = 0;
  std::uint64_t k_ = 0;  ///< index of the next due time
  std::uint64_t next_tick_ = std::numeric_limits<std::uint64_t>::max();
};

}  // namespace domel::platform
