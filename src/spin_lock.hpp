// Locks of one byte for the parallel propagation: each guards a face's lists or one vertex for a few dozen
// instructions, so waiting spins rather than sleeping; with more threads than cores the holder may be
// waiting for a core, so a long wait yields it.
#pragma once

#include <atomic>
#include <cstdint>

#include "worker_pool.hpp"

namespace exactgeo::detail {

class SpinGuard {
 public:
  explicit SpinGuard(std::atomic<std::uint8_t>& lock) : lock_(lock) {
    while (lock_.exchange(1, std::memory_order_acquire) != 0)
      wait_until([&] { return lock_.load(std::memory_order_relaxed) == 0; });
  }
  ~SpinGuard() { lock_.store(0, std::memory_order_release); }
  SpinGuard(const SpinGuard&) = delete;
  SpinGuard& operator=(const SpinGuard&) = delete;

 private:
  std::atomic<std::uint8_t>& lock_;
};

}  // namespace exactgeo::detail
