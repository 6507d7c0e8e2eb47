// Timing of the engine's phases (GeodesicOptions::collect_timings).
#pragma once

#include <chrono>

namespace exactgeo::detail {

// Adds the time until it goes out of scope to `bucket`, if timing is on; costs one branch otherwise.
class PhaseTimer {
 public:
  PhaseTimer(bool on, double& bucket) : bucket_(on ? &bucket : nullptr) {
    if (bucket_) start_ = std::chrono::steady_clock::now();
  }
  ~PhaseTimer() {
    if (bucket_) *bucket_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  double* bucket_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace exactgeo::detail
