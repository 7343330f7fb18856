// SPDX-License-Identifier: MIT
// The stop request of interrupt.hpp: one atomic int.
#include "core/interrupt.hpp"

#include <atomic>

#include <time.h>

namespace domel::platform {

namespace {
std::atomic<int> g_signal{0};
std::atomic<long long> g_since_ns{0};  ///< CLOCK_MONOTONIC at the first request
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");
static_assert(std::atomic<long long>::is_always_lock_free, "a signal handler may only touch lock-free atomics");

long long now_ns() noexcept {  // clock_gettime is async-signal-safe (POSIX)
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<long long>(t.tv_sec) * 1000000000LL + t.tv_nsec;
}
}  // namespace

void request_interrupt(int signal) noexcept {
  if (g_signal.load(std::memory_order_relaxed) == 0) g_since_ns.store(now_ns(), std::memory_order_relaxed);
  g_signal.store(signal, std::memory_order_relaxed);
}

bool stop_overdue() noexcept {
  return g_signal.load(std::memory_order_relaxed) != 0 &&
         static_cast<double>(now_ns() - g_since_ns.load(std::memory_order_relaxed)) > kStopGraceSeconds * 1e9;
}
int interrupt_requested() noexcept { return g_signal.load(std::memory_order_relaxed); }
void clear_interrupt() noexcept { g_signal.store(0, std::memory_order_relaxed); }

void stop_point(const std::string& what) {
  if (stop_overdue()) throw StoppedMidStep("stopped on request in " + what);
}

}  // namespace domel::platform
