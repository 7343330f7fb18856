// SPDX-License-Identifier: MIT
// The worker team: a generation counter announces each job; workers spin a
// few microseconds on it (cheap on an idle machine) before sleeping on a
// condition variable (cheap on a busy one).
#include "core/thread_pool.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace domel::platform {

namespace {
// Waiting: first a bounded busy spin on the atomic (a step's fork/join gaps
// are microseconds), then yields, then sleep on the condition variable.
// The spin has no PAUSE instruction: in a VM, PAUSE loops can trigger
// pause-loop exits that deschedule the spinning vCPU. An empty fork/join
// costs ~3 us on the 2-core development VM (20 000 in a row), and stays
// ~3-6 us with 30-100 us of serial work between forks.
constexpr int kBusy = 20000;
constexpr int kSpin = 2000;

/// Busy-spin, then yield, until done() holds or both budgets are spent;
/// the caller then sleeps on its condition variable if still needed.
template <class Done>
void spin_until(Done&& done) {
  for (int k = 0; k < kBusy && !done(); ++k) {
  }
  for (int k = 0; k < kSpin && !done(); ++k) std::this_thread::yield();
}
}  // namespace

int default_thread_count() {
  const char* env = std::getenv("DOMEL_THREADS");
  if (env == nullptr || *env == '\0') return 1;
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(env, &end, 10);
  if (*end != '\0' || errno != 0 || n < 1 || n > 256)
    throw std::invalid_argument(std::string("the environment variable DOMEL_THREADS expects an integer from 1 to 256, found '") +
                                env + "'");
  return static_cast<int>(n);
}

ThreadPool::ThreadPool(int threads) : size_(std::max(1, threads)), errors_(static_cast<std::size_t>(size_)) {
  for (int t = 1; t < size_; ++t) workers_.emplace_back([this, t] { worker(t); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::run(const std::function<void(int)>& fn) {
  if (size_ == 1) {
    fn(0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    std::fill(errors_.begin(), errors_.end(), nullptr);
    pending_.store(size_ - 1);
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  try {
    fn(0);
  } catch (...) {
    errors_[0] = std::current_exception();
  }
  spin_until([this] { return pending_.load(std::memory_order_acquire) == 0; });
  if (pending_.load() > 0) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_.load() == 0; });
  }
  for (const auto& e : errors_)
    if (e) std::rethrow_exception(e);
}

void ThreadPool::worker(int t) {
  std::uint64_t seen = 0;
  for (;;) {
    spin_until([&] { return generation_.load(std::memory_order_acquire) != seen; });
    const std::function<void(int)>* job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return generation_.load() != seen; });
      seen = generation_.load();
      if (stop_) return;
      job = job_;
    }
    try {
      (*job)(t);
    } catch (...) {
      errors_[static_cast<std::size_t>(t)] = std::current_exception();
    }
    if (pending_.fetch_sub(1) == 1) {
      std::lock_guard<std::mutex> lock(mutex_);
      done_.notify_one();
    }
  }
}

}  // namespace domel::platform
