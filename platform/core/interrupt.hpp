// SPDX-License-Identifier: MIT
// A request to stop a run early (SIGINT, SIGTERM): the command line's signal
// handler records the signal, and the run loop looks at it once per macro
// step, finishes that step, writes a checkpoint and its outputs and returns
// (scheduler/simulation.cpp); loops that can take longer than a second within
// a step ask it too (stop_point, and plugins through abi.h's stop_requested).
// Only a lock-free atomic is touched, so the handler is async-signal-safe.
#pragma once

#include <stdexcept>
#include <string>

namespace domel::platform {

/// Thrown where a long operation inside a macro step or the set-up (many
/// insertion attempts of the coupling's inflow, a plugin's long loop that
/// asked the host, abi.h stop_requested) gives up on a stop request within
/// a second: the step is not finished, so nothing of it is written, and the
/// command line reports the run as interrupted with its last checkpoint.
class StoppedMidStep : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A stop request waits this long for the macro step to end by itself (with
/// a checkpoint) before the loops inside it give up (stop_overdue).
inline constexpr double kStopGraceSeconds = 1.0;

/// True when a stop was requested more than kStopGraceSeconds ago: the step
/// in progress is taking too long to end by itself.
bool stop_overdue() noexcept;

/// Throws StoppedMidStep("stopped on request in " + what) when stop_overdue().
/// For loops that may run long: call it every few thousand iterations.
void stop_point(const std::string& what);

/// Record that `signal` asked the run to stop (from a signal handler).
void request_interrupt(int signal) noexcept;
/// The signal that asked the run to stop, 0 when none.
int interrupt_requested() noexcept;
/// Forget a request (before a new run in the same process).
void clear_interrupt() noexcept;

}  // namespace domel::platform
