// SPDX-License-Identifier: MIT
// The scheduler's one notion of "every so often": an Interval of simulated
// time, used by every periodic action of a run (VTK frames, probe rows, grid
// files, pour events, deletion and mass-flow plane checks, and the couplings
// still to come), with one tolerance for comparing a time with a due time;
// and the hook lists that run before and after every macro step.
//
// Due times are first + k * period, computed from k rather than summed, so
// that round-off does not accumulate over a long run; a time t counts as
// having reached a due time d when t >= d - kTimeTolerance * macro step (t is
// always a multiple of the macro step, which round-off may leave a hair
// short of a due time that is exactly on it).
//
// Cell-grid sampling ("every N steps", output.grids[].every) is not an
// Interval: it counts the steps of one subdomain, sub-cycles included, an
// exact integer clock that needs no tolerance (CellGrid::due). Only actions
// at macro-step boundaries use Interval.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace domel::platform {

class Subdomain;

/// Fraction of the macro step by which a time may fall short of a due time
/// and still count as having reached it.
inline constexpr double kTimeTolerance = 1e-9;

/// The macro step of a set of subdomains: the largest time step.
double macro_step_of(const std::vector<std::unique_ptr<Subdomain>>& subdomains);

/// Sub-steps of a subdomain of time step dt within a macro step: rounded up,
/// so that no step grows (the subdomain then steps with macro / n).
int substeps_of(double macro, double dt);

/// A periodic action in simulated time: due at first, first + period,
/// first + 2 period, ... A default-constructed Interval (or period <= 0) is
/// never due.
class Interval {
 public:
  Interval() = default;
  /// `macro_step` sets the tolerance (kTimeTolerance x macro_step).
  Interval(double period, double first, double macro_step);

  bool enabled() const { return period_ > 0; }
  /// True when t has reached the next due time.
  bool due(double t) const { return period_ > 0 && t >= next_ - tolerance_; }
  /// Move the next due time past t: the first due time that t has not reached.
  void advance(double t);
  /// due(t), and if so advance(t): "is it time, and mark it done".
  bool take(double t) {
    if (!due(t)) return false;
    advance(t);
    return true;
  }
  double next() const { return next_; }
  /// Index of the next due time (checkpoints), and going on from one.
  std::uint64_t index() const { return k_; }
  void resume(std::uint64_t k) {
    k_ = k;
    if (period_ > 0) next_ = first_ + static_cast<double>(k_) * period_;
  }
  double period() const { return period_; }
  double tolerance() const { return tolerance_; }

 private:
  double period_ = 0;
  double first_ = 0;
  double tolerance_ = 0;
  std::uint64_t k_ = 0;  ///< index of the next due time
  double next_ = std::numeric_limits<double>::infinity();
};

/// What a macro-step hook sees: the simulated time at the hook (the start of
/// the macro step for `before`, its end for `after`), the macro step's index
/// and length, and the subdomains. One object lives for the whole run and is
/// updated in place, so calling the hooks allocates nothing.
struct MacroStep {
  double t = 0;                 ///< [s]
  double macro = 0;             ///< [s] the macro step
  std::uint64_t index = 0;      ///< m: the macro step that starts (before) or has ended (after)
  std::vector<std::unique_ptr<Subdomain>>* subdomains = nullptr;
};

/// Hook lists of the run loop. `before` hooks run at the start of every
/// macro step that is stepped (not at the final time), before that step's
/// outputs; `after` hooks run after all subdomains have finished the macro
/// step. Each list runs in registration order. An empty list costs one
/// comparison per macro step.
struct MacroHooks {
  using Hook = std::function<void(const MacroStep&)>;
  std::vector<Hook> before;
  std::vector<Hook> after;

  static void run(const std::vector<Hook>& hooks, const MacroStep& step) {
    for (const auto& h : hooks) h(step);
  }
};

}  // namespace domel::platform
