// A hint that memory will be read soon. The propagation's bookkeeping waits on cache misses spread over
// many small records (lists, face frames, distances); where the next record is known ahead of its use,
// asking for it early overlaps those waits with the work in between.
#pragma once

namespace exactgeo::detail {

inline void prefetch(const void* address) {
#if defined(__GNUC__)
  __builtin_prefetch(address);
#else
  (void)address;
#endif
}

}  // namespace exactgeo::detail
