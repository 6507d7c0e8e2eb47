// A hint that memory will be read soon. The propagation's bookkeeping waits on cache misses spread over
// many small records (lists, face frames, distances); where the next record is known ahead of its use,
// asking for it early overlaps those waits with the work in between.
#pragma once

namespace exactgeo::detail {

// An instruction the compiler must keep. GCC 12's mod/ref analysis takes a function whose only statements
// are __builtin_prefetch calls for one without effects and deletes its calls (-fno-ipa-modref keeps them):
// once the hints became inline members of EngineState, every prefetch of the parallel bands' steps and
// several of the one-thread loop's were gone, and two threads ran 5-18% slower. The operand only names the
// address: a prefetch reads nothing and never faults.
inline void prefetch(const void* address) {
#if defined(__GNUC__) && defined(__x86_64__)
  __asm__ volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(address)));
#elif defined(__GNUC__) && defined(__aarch64__)
  __asm__ volatile("prfm pldl1keep, %0" : : "Q"(*static_cast<const char*>(address)));
#elif defined(__GNUC__)
  __builtin_prefetch(address);
#else
  (void)address;
#endif
}

}  // namespace exactgeo::detail
