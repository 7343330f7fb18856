// SPDX-License-Identifier: MIT
// A fixed team of worker threads for the per-step loops. run(fn) calls
// fn(t) for t = 0..size()-1 (t = 0 on the calling thread) and returns when
// all are done, rethrowing the first exception. Work is split statically
// (range(t) below), so which thread computes what never depends on timing:
// results are reproducible for a given team size.
//
// Why not OpenMP: libgomp spins while waiting by default and reads its wait
// policy from the environment before main() runs; on a loaded machine (CI
// running tests in parallel, a user compiling) a spinning team of two on two
// busy cores ran 100x slower. Here workers spin briefly, then block.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace domel::platform {

/// The thread count used where neither the command line (--threads) nor the
/// scenario (run.threads) sets one: the environment variable DOMEL_THREADS
/// (an integer 1..256), else 1. Lets a whole test suite run threaded.
/// Throws std::invalid_argument naming the variable when it is set to
/// anything else.
int default_thread_count();

class ThreadPool {
 public:
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return size_; }
  void run(const std::function<void(int)>& fn);

  /// The t-th of size() contiguous, near-equal parts of [0, n).
  std::pair<std::size_t, std::size_t> range(std::size_t n, int t) const {
    return {n * static_cast<std::size_t>(t) / size_, n * static_cast<std::size_t>(t + 1) / size_};
  }
  /// run() over a static partition of [0, n): fn(begin, end, t).
  template <class F>
  void for_range(std::size_t n, F&& fn) {
    if (size_ == 1) {
      fn(std::size_t{0}, n, 0);
      return;
    }
    run([&](int t) {
      const auto r = range(n, t);
      fn(r.first, r.second, t);
    });
  }

 private:
  void worker(int t);
  int size_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<int> pending_{0};
  bool stop_ = false;
  const std::function<void(int)>* job_ = nullptr;
  std::vector<std::exception_ptr> errors_;
};

}  // namespace domel::platform
