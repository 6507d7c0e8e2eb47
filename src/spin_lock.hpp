// Locks of one byte for the parallel propagation: each guards a face's lists or one vertex for a few dozen
// instructions, so waiting spins rather than sleeping; with more threads than cores the holder may be
// waiting for a core, so a long wait yields it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

#include "worker_pool.hpp"

namespace exactgeo::detail {

// The waits of the calling thread for a SpinGuard's lock (GeodesicStats::parallel_lock_waits): a lock
// found taken costs a count, and two clock reads when `timed` (collect_timings). Per thread, so that the
// count costs no shared write.
struct LockWaits {
  std::uint64_t count = 0;
  double seconds = 0.0;
  bool timed = false;
};
inline thread_local LockWaits lock_waits;

class SpinGuard {
 public:
  explicit SpinGuard(std::atomic<std::uint8_t>& lock) : lock_(lock) {
    if (lock_.exchange(1, std::memory_order_acquire) != 0) wait();
  }
  ~SpinGuard() { lock_.store(0, std::memory_order_release); }
  SpinGuard(const SpinGuard&) = delete;
  SpinGuard& operator=(const SpinGuard&) = delete;

 private:
  [[gnu::noinline]] void wait() {
    LockWaits& waits = lock_waits;
    ++waits.count;
    const auto start = waits.timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
    do {
      wait_until([&] { return lock_.load(std::memory_order_relaxed) == 0; });
    } while (lock_.exchange(1, std::memory_order_acquire) != 0);
    if (waits.timed) waits.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  std::atomic<std::uint8_t>& lock_;
};

}  // namespace exactgeo::detail
