// SPDX-License-Identifier: MIT
// A request to stop a run early (SIGINT, SIGTERM): the command line's signal
// handler records the signal, and the run loop looks at it once per macro
// step, finishes that step, writes a checkpoint and its outputs and returns
// (scheduler/simulation.cpp). Only a lock-free atomic is touched, so the
// handler is async-signal-safe.
#pragma once

namespace domel::platform {

/// Record that `signal` asked the run to stop (from a signal handler).
void request_interrupt(int signal) noexcept;
/// The signal that asked the run to stop, 0 when none.
int interrupt_requested() noexcept;
/// Forget a request (before a new run in the same process).
void clear_interrupt() noexcept;

}  // namespace domel::platform
