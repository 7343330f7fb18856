// SPDX-License-Identifier: MIT
// Guards the scheduler's one interval type (platform/scheduler/schedule):
// due times first + k period with one tolerance of kTimeTolerance x macro
// step, catching up past a late time in one advance, no drift over a long
// run, never due when disabled; and the macro-step hook lists run in order.
#include <gtest/gtest.h>

#include <vector>

#include "scheduler/schedule.hpp"

namespace {

using domel::platform::Interval;
using domel::platform::kTimeTolerance;
using domel::platform::MacroHooks;
using domel::platform::MacroStep;

TEST(Interval, IsDueFromItsFirstTimeWithinTheToleranceAndAdvancesPastTheTimeGiven) {
  const double macro = 1e-3;
  Interval iv(0.01, 0.005, macro);
  EXPECT_FALSE(iv.due(0.004));
  EXPECT_TRUE(iv.due(0.005 - 0.5 * kTimeTolerance * macro));  // round-off short of the due time
  EXPECT_FALSE(iv.due(0.005 - 2 * kTimeTolerance * macro));
  EXPECT_TRUE(iv.take(0.005));
  EXPECT_DOUBLE_EQ(iv.next(), 0.015);
  EXPECT_FALSE(iv.take(0.010));
  iv.advance(0.047);  // late: skips the missed due times in one call
  EXPECT_DOUBLE_EQ(iv.next(), 0.055);
}

TEST(Interval, DueTimesDoNotDriftOverAMillionPeriods) {
  // summing 0.1 a million times drifts by ~1e-6 relative; first + k period does not
  const double macro = 0.1;
  Interval iv(0.1, 0.0, macro);
  std::uint64_t fired = 0;
  for (std::uint64_t m = 0; m <= 1000000; ++m)
    if (iv.take(static_cast<double>(m) * macro)) ++fired;
  EXPECT_EQ(fired, 1000001u);
}

TEST(Interval, APeriodBelowTheMacroStepFiresEveryMacroStep) {
  Interval iv(1e-9, 0.0, 1e-3);
  int fired = 0;
  for (int m = 0; m < 10; ++m) fired += iv.take(m * 1e-3) ? 1 : 0;
  EXPECT_EQ(fired, 10);
  EXPECT_GT(iv.next(), 9e-3);
}

TEST(Interval, ADisabledIntervalIsNeverDue) {
  EXPECT_FALSE(Interval().due(1e30));
  EXPECT_FALSE(Interval(0.0, 0.0, 1e-3).due(0.0));
}

TEST(MacroHooks, RunInRegistrationOrderWithTheStepTheyAreGiven) {
  MacroHooks hooks;
  std::vector<int> calls;
  hooks.before.push_back([&](const MacroStep& s) { calls.push_back(static_cast<int>(s.index) * 10 + 1); });
  hooks.before.push_back([&](const MacroStep& s) { calls.push_back(static_cast<int>(s.index) * 10 + 2); });
  MacroStep step;
  step.index = 3;
  MacroHooks::run(hooks.before, step);
  MacroHooks::run(hooks.after, step);  // empty: nothing
  EXPECT_EQ(calls, (std::vector<int>{31, 32}));
}

}  // namespace
