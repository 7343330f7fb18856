// SPDX-License-Identifier: MIT
// Guards the run's one cadence type (platform/core/cadence.hpp): in time,
// due at the first tick that reaches first + k period within kTimeTolerance
// x tick, catching up past a late tick in one advance, no drift over a long
// run, several due times within one tick firing once; in ticks, due every n
// ticks exactly; never due when disabled; and a restart going on from the
// index it was checkpointed at, or past the checkpoint's tick when the
// period changed; a period below what the times resolve firing every tick
// without looping, and the refusal of an interval below the tick.
#include <gtest/gtest.h>

#include "core/cadence.hpp"

#include <cstdint>
#include <string>

namespace {

using domel::platform::Cadence;
using domel::platform::kTimeTolerance;

TEST(Cadence, InTimeIsDueAtTheFirstTickThatReachesItsTimeWithinTheTolerance) {
  const double tick = 1e-3;
  // 0.005 + half the tolerance: tick 5 (its time is a hair short) reaches it
  Cadence c = Cadence::in_time(0.01, 0.005 + 0.5 * kTimeTolerance * tick, tick);
  EXPECT_FALSE(c.due(4));
  EXPECT_TRUE(c.due(5));
  // twice the tolerance: tick 5 does not, tick 6 does
  Cadence late = Cadence::in_time(0.01, 0.005 + 2 * kTimeTolerance * tick, tick);
  EXPECT_FALSE(late.due(5));
  EXPECT_TRUE(late.due(6));
  EXPECT_TRUE(c.take(5));
  EXPECT_DOUBLE_EQ(c.next_time(), 0.015 + 0.5 * kTimeTolerance * tick);
  EXPECT_FALSE(c.take(10));
  c.advance(47);  // late: skips the missed due times in one call
  EXPECT_DOUBLE_EQ(c.next_time(), 0.055 + 0.5 * kTimeTolerance * tick);
  EXPECT_EQ(c.index(), 5u);
}

TEST(Cadence, DueTimesDoNotDriftOverAMillionPeriods) {
  // summing 0.1 a million times drifts by ~1e-6 relative; first + k period does not
  Cadence c = Cadence::in_time(0.1, 0.0, 0.1);
  std::uint64_t fired = 0;
  for (std::uint64_t m = 0; m <= 1000000; ++m)
    if (c.take(m)) ++fired;
  EXPECT_EQ(fired, 1000001u);
}

TEST(Cadence, APeriodBelowTheTickFiresEveryTick) {
  Cadence c = Cadence::in_time(1e-9, 0.0, 1e-3);
  int fired = 0;
  for (std::uint64_t m = 0; m < 10; ++m) fired += c.take(m) ? 1 : 0;
  EXPECT_EQ(fired, 10);
  EXPECT_GT(c.next_time(), 9e-3);
}

// Issue 41: a period far below what the times resolve (1e-22 s on a clock of
// 1e-5 s; 1e-300 s after a first time of 0.5 s, where first + k period no
// longer grows with k) used to loop for ever in advance(). Each take() now
// ends after a few periods, and the cadence fires at every tick from the
// first one that reaches its first time, as any period below the tick does.
// 100 000 ticks, a few milliseconds.
TEST(Cadence, APeriodBelowWhatTheTimesResolveFiresEveryTickAndNeverLoops) {
  const double tick = 1e-5;
  Cadence tiny = Cadence::in_time(1e-22, 0.0, tick);
  Cadence lost = Cadence::in_time(1e-300, 0.5, tick);
  std::uint64_t fired_tiny = 0, fired_lost = 0;
  for (std::uint64_t m = 0; m < 100000; ++m) {
    fired_tiny += tiny.take(m) ? 1 : 0;
    fired_lost += lost.take(m) ? 1 : 0;
  }
  EXPECT_EQ(fired_tiny, 100000u);
  EXPECT_EQ(fired_lost, 100000u - 50000u);  // ticks 50000 .. 99999 reach 0.5 s
}

TEST(Cadence, AnIntervalBelowTheTickIsRefusedWithTheStepAndTheValue) {
  EXPECT_EQ(domel::platform::schedule_refusal(1e-5, 1e-5, "frames"), "");
  EXPECT_EQ(domel::platform::schedule_refusal(0.0, 1e-5, "frames"), "");  // off
  EXPECT_EQ(domel::platform::schedule_refusal(1e-5 * (1 - 0.5 * kTimeTolerance), 1e-5, "frames"), "");
  const std::string why = domel::platform::schedule_refusal(1e-22, 1e-5, "frames");
  EXPECT_NE(why.find("expected at least the macro step, 1e-05 s"), std::string::npos) << why;
  EXPECT_NE(why.find("frames"), std::string::npos) << why;
  EXPECT_NE(why.find("found 1e-22 s"), std::string::npos) << why;
}

TEST(Cadence, InTicksIsDueEveryNTicksFromTheFirst) {
  const Cadence every3 = Cadence::in_ticks(3);
  for (std::uint64_t m : {0u, 3u, 6u, 99u}) EXPECT_TRUE(every3.on(m)) << m;
  for (std::uint64_t m : {1u, 2u, 4u, 100u}) EXPECT_FALSE(every3.on(m)) << m;
  const Cadence from8 = Cadence::in_ticks(8, 8);  // a coupling's control clock: not at 0
  EXPECT_FALSE(from8.on(0));
  EXPECT_TRUE(from8.on(8));
  EXPECT_TRUE(from8.on(40));
  Cadence taken = Cadence::in_ticks(4, 2);
  EXPECT_FALSE(taken.due(1));
  EXPECT_TRUE(taken.take(2));
  EXPECT_FALSE(taken.due(5));
  EXPECT_TRUE(taken.take(9));  // late: 6 was missed, the next is 10
  EXPECT_FALSE(taken.due(9));
  EXPECT_TRUE(taken.due(10));
}

TEST(Cadence, ADisabledCadenceIsNeverDue) {
  EXPECT_FALSE(Cadence().due(std::uint64_t{1} << 60));
  EXPECT_FALSE(Cadence::in_time(0.0, 0.0, 1e-3).due(0));
  EXPECT_FALSE(Cadence::in_ticks(0).on(0));
}

TEST(Cadence, ARestartGoesOnFromItsIndexOrPastTheCheckpointWhenThePeriodChanged) {
  Cadence ran = Cadence::in_time(0.01, 0.0, 1e-3);
  for (std::uint64_t m = 0; m <= 25; ++m) ran.take(m);  // due at 0, 10, 20: next 30
  Cadence same = Cadence::in_time(0.01, 0.0, 1e-3);
  same.restore(ran.index(), 0.01, 26);
  EXPECT_EQ(same.index(), ran.index());
  EXPECT_FALSE(same.due(29));
  EXPECT_TRUE(same.due(30));
  Cadence other = Cadence::in_time(0.004, 0.0, 1e-3);  // the period changed: from the checkpoint's tick on
  other.restore(ran.index(), 0.01, 26);
  EXPECT_FALSE(other.due(26));
  EXPECT_TRUE(other.due(28));
}

}  // namespace
