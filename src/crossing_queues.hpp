// The crossing queues of the parallel propagation (parallel_propagation.cpp): during a band, the lists each thread
// scheduled to cross, crossed last in first out by that thread alone. The newest lie where it just worked,
// still in its cache (on one thread the order gains nothing: docs/performance.md). A thread that runs out says
// it is hungry; the next thread to notice hands it the older half of its own lists through its inbox.
//
// There is no shared count of lists: a band is over when every thread that joined it is hungry at once, since
// only a thread with a list to cross makes new ones. A thread the system starts late finds the band over
// and does not join.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "spin_lock.hpp"
#include "worker_pool.hpp"

namespace exactgeo::detail {

class CrossingQueues {
 public:
  // Queues for `threads` threads, all empty.
  explicit CrossingQueues(unsigned threads) : threads_(threads), queues_(std::make_unique<Queue[]>(threads)) {}

  unsigned threads() const { return threads_; }

  // Between bands, on one thread: a new band, whose first lists (those scheduled before it) go with share 0.
  void start_band(std::span<const std::uint32_t> first_lists) {
    for (unsigned t = 0; t < threads_; ++t) {  // each ended the last band hungry and unfed
      queues_[t].hungry.store(false, std::memory_order_relaxed);
      queues_[t].fed.store(false, std::memory_order_relaxed);
      queues_[t].share_taken.store(false, std::memory_order_relaxed);
    }
    first_lists_.assign(first_lists.begin(), first_lists.end());
    state_.store(0, std::memory_order_relaxed);
  }

  // Counts the calling thread in, unless the band is over (false: it takes no part).
  bool join() {
    std::uint64_t state = state_.load(std::memory_order_acquire);
    do {
      if (state & kBandOver) return false;
    } while (!state_.compare_exchange_weak(state, state + kJoined, std::memory_order_acq_rel));
    return true;
  }

  // Claims share `share` of the band's vertices for `thread`: true for the first thread to ask. The band's first
  // lists come with share 0 into the thread's queue. With them given to a share rather than to thread 0, a
  // thread that joins late (the system ran it late) cannot hold lists that no one crosses: a thread claims
  // every share it finds unclaimed before it may be hungry, so every share is claimed before the band ends.
  bool claim_share(unsigned share, unsigned thread) {
    if (queues_[share].share_taken.exchange(true, std::memory_order_relaxed)) return false;
    if (share == 0) queues_[thread].items.insert(queues_[thread].items.end(), first_lists_.begin(), first_lists_.end());
    return true;
  }

  // Thread `thread`'s own queue, used by it alone while it is not hungry.
  void push(unsigned thread, std::uint32_t list) { queues_[thread].items.push_back(list); }
  bool pop(unsigned thread, std::uint32_t& list) {
    Queue& queue = queues_[thread];
    if (queue.front == queue.items.size()) return false;
    list = queue.items.back();
    queue.items.pop_back();
    if (queue.front == queue.items.size()) {  // what is left was handed over: start afresh
      queue.items.clear();
      queue.front = 0;
    }
    return true;
  }

  bool anyone_hungry() const { return hungry_count(state_.load(std::memory_order_relaxed)) > 0; }

  // Hands the older half of `thread`'s lists to each hungry thread. It keeps the newer half, which it crosses
  // first: it scheduled those last, so their records and faces are still in its cache (handing over the newer
  // half instead was 2-3% slower at 400K faces). The one fed is counted as no longer hungry before it knows:
  // the count never shows every thread hungry while lists move between them (this one is not).
  void feed_hungry(unsigned thread) {
    Queue& queue = queues_[thread];
    for (unsigned k = 1; k < threads_ && queue.items.size() - queue.front >= 2; ++k) {
      Queue& other = queues_[(thread + k) % threads_];
      if (!other.hungry.load(std::memory_order_acquire)) continue;
      const SpinGuard guard(other.inbox_lock);
      if (!other.hungry.load(std::memory_order_relaxed)) continue;
      const auto oldest = queue.items.begin() + static_cast<std::ptrdiff_t>(queue.front);
      const std::size_t given = (queue.items.size() - queue.front) / 2;
      other.inbox.assign(oldest, oldest + static_cast<std::ptrdiff_t>(given));
      queue.front += given;
      other.hungry.store(false, std::memory_order_relaxed);
      state_.fetch_sub(kHungry, std::memory_order_acq_rel);
      other.fed.store(true, std::memory_order_release);
    }
  }

  // For `thread`, out of lists: says it is hungry and waits, spinning `spins` times before yielding the core,
  // until it is fed (true: its queue holds the lists handed over) or the band is over or aborted (false).
  bool wait_for_lists(unsigned thread, int spins) {
    Queue& queue = queues_[thread];
    // Counted before it says so: a thread that sees it hungry finds it counted.
    state_.fetch_add(kHungry, std::memory_order_acq_rel);
    queue.hungry.store(true, std::memory_order_release);
    wait_until([&] { return band_over_or_fed(queue); }, spins);
    if (!queue.fed.load(std::memory_order_acquire)) return false;
    const SpinGuard guard(queue.inbox_lock);
    queue.items.swap(queue.inbox);
    queue.fed.store(false, std::memory_order_relaxed);
    return true;
  }

  // A thread threw: the others stop, as the lists they would wait for will not come.
  void abort() { aborted_.store(true, std::memory_order_relaxed); }
  bool aborted() const { return aborted_.load(std::memory_order_relaxed); }

 private:
  struct alignas(64) Queue {  // a cache line of its own: its thread writes it often
    std::vector<std::uint32_t> items;
    std::size_t front = 0;  // the lists before it were handed to hungry threads
    std::atomic<bool> hungry{false};
    std::atomic<bool> fed{false};          // the inbox holds lists
    std::atomic<bool> share_taken{false};  // the band's share of vertices of the same number as the thread
    std::atomic<std::uint8_t> inbox_lock{0};
    std::vector<std::uint32_t> inbox;
  };

  // state_: the threads that joined the band (high half), those of them hungry (low half), and kBandOver once
  // every one that joined is hungry.
  static constexpr std::uint64_t kJoined = std::uint64_t{1} << 32, kHungry = 1, kBandOver = std::uint64_t{1} << 63;
  static constexpr std::uint64_t hungry_count(std::uint64_t state) { return state & 0xffffffffu; }
  static constexpr std::uint64_t joined_count(std::uint64_t state) { return (state & ~kBandOver) >> 32; }

  // For a hungry thread: whether it was fed, or the band is over (it closes the band if every thread that
  // joined is hungry: only a thread with lists makes new ones, and every share of vertices was taken before
  // any thread got hungry).
  bool band_over_or_fed(const Queue& queue) {
    if (queue.fed.load(std::memory_order_acquire) || aborted()) return true;
    std::uint64_t state = state_.load(std::memory_order_acquire);
    while (!(state & kBandOver)) {
      if (hungry_count(state) != joined_count(state)) return false;
      if (state_.compare_exchange_weak(state, state | kBandOver, std::memory_order_acq_rel)) return true;
    }
    return true;
  }

  unsigned threads_;
  std::unique_ptr<Queue[]> queues_;
  std::vector<std::uint32_t> first_lists_;  // of the band under way, until share 0 is claimed
  std::atomic<std::uint64_t> state_{0};
  std::atomic<bool> aborted_{false};
};

}  // namespace exactgeo::detail
