// SPDX-License-Identifier: MIT
// The stop request (core/interrupt.hpp): a loop inside a macro step gives up
// on it only once it is older than kStopGraceSeconds, so that a step which
// ends by itself within the grace still ends with a checkpoint. Cost: 1.1 s
// (the grace waited out once).
#include "core/interrupt.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <string>
#include <thread>

namespace {

using namespace domel::platform;

TEST(StopRequest, LoopsInsideAStepGiveUpOnlyAfterTheGrace) {
  clear_interrupt();
  EXPECT_FALSE(stop_overdue());
  EXPECT_NO_THROW(stop_point("a loop"));
  request_interrupt(SIGTERM);
  EXPECT_EQ(interrupt_requested(), SIGTERM);
  EXPECT_FALSE(stop_overdue()) << "within the grace the step may still end by itself";
  EXPECT_NO_THROW(stop_point("a loop"));
  std::this_thread::sleep_for(std::chrono::duration<double>(kStopGraceSeconds + 0.1));
  EXPECT_TRUE(stop_overdue());
  try {
    stop_point("the inflow of coupling 'c'");
    FAIL() << "expected StoppedMidStep";
  } catch (const StoppedMidStep& e) {
    EXPECT_EQ(std::string(e.what()), "stopped on request in the inflow of coupling 'c'");
  }
  request_interrupt(SIGINT);  // a second request keeps the first one's time
  EXPECT_TRUE(stop_overdue());
  clear_interrupt();
  EXPECT_FALSE(stop_overdue());
}

}  // namespace
