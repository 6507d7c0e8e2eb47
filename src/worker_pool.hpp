// A small fork-join team of threads for the parallel single-source propagation: the engine hands it a batch
// of independent items thousands of times per run, each batch some microseconds of work, so the workers
// spin briefly between batches before they sleep (a wake-up from sleep takes longer than a batch). The
// caller works on the batch too and waits only for items other threads have taken: a worker the system
// does not schedule in time just misses the batch instead of holding it up.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace exactgeo::detail {

// The thread count a setting asks for: 0 means one per core (one where the count of cores is unknown).
inline unsigned threads_or_cores(unsigned threads) {
  return threads != 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
}

class WorkerPool {
 public:
  // `threads` in all, the calling thread included.
  explicit WorkerPool(unsigned threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  unsigned threads() const { return static_cast<unsigned>(workers_.size()) + 1; }

  // Calls task(item, thread) for every item in [0, count), spread over the threads (thread 0 is the
  // caller), and returns when all are done. Which thread runs an item is left to chance: tasks must write
  // only to what their item and their thread own. An exception from a task is rethrown here (the first).
  void run(std::size_t count, const std::function<void(std::size_t, unsigned)>& task);

 private:
  void work(unsigned thread);
  void take_items(unsigned thread);
  void publish(std::uint64_t next);

  std::vector<std::jthread> workers_;
  // The batch: its number in the high 32 bits, the next item to take in the low ones. Taking an item is a
  // compare-and-swap on it, so a thread that still thinks an older batch is on cannot take anything.
  std::atomic<std::uint64_t> next_{0};
  std::atomic<const std::function<void(std::size_t, unsigned)>*> task_{nullptr};
  std::atomic<std::size_t> count_{0};
  std::atomic<std::size_t> done_{0};
  std::atomic<bool> failed_{false};
  std::atomic<bool> stopping_{false};
  std::mutex mutex_;  // for sleeping workers, and the first failure
  std::condition_variable wake_;
  std::exception_ptr failure_;
};

// ------------------------------------------------------------------------------------------------------
// Implementation (in the header, so that the tests can drive the team directly).
namespace worker_pool_detail {

// How long a worker spins for the next batch before it sleeps: batches follow each other within
// microseconds while a propagation runs; between runs the workers should not burn a core.
inline constexpr auto kSpinTime = std::chrono::microseconds(200);

inline void pause_briefly() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

inline std::uint32_t batch_of(std::uint64_t next) { return static_cast<std::uint32_t>(next >> 32); }

// The item part of a batch's counter once the batch is over: above any item count.
inline constexpr std::uint64_t kClosed = 0xffffffffu;

}  // namespace worker_pool_detail


inline WorkerPool::WorkerPool(unsigned threads) {
  for (unsigned t = 1; t < threads; ++t) workers_.emplace_back([this, t] { work(t); });
}

inline WorkerPool::~WorkerPool() {
  stopping_ = true;
  publish(next_.load() + (std::uint64_t{1} << 32));
  workers_.clear();  // joins
}

// Starts a batch (or the shutdown). Stored under the mutex, so that a worker about to sleep either sees it
// or gets the wake-up.
inline void WorkerPool::publish(std::uint64_t next) {
  {
    const std::lock_guard lock(mutex_);
    next_.store(next, std::memory_order_release);
  }
  wake_.notify_all();
}

inline void WorkerPool::take_items(unsigned thread) {
  std::uint64_t next = next_.load(std::memory_order_acquire);
  while (true) {
    const std::function<void(std::size_t, unsigned)>* task = task_.load(std::memory_order_acquire);
    const std::size_t count = count_.load(std::memory_order_acquire);
    const std::size_t first = next & 0xffffffffu;
    if (first >= count) return;
    // Items are taken a few at a time: one shared counter touched per item would cost more than the items
    // on a batch of small ones, and neighbouring items then stay on one thread. About eight takes per thread
    // keep the threads' shares even.
    const std::size_t end = std::min(count, first + std::max<std::size_t>(1, count / (8 * threads())));
    // Fails if another thread took the items or a new batch began (then task and count may be stale).
    if (!next_.compare_exchange_weak(next, next + (end - first), std::memory_order_acq_rel)) continue;
    for (std::size_t item = first; item < end && !failed_.load(std::memory_order_relaxed); ++item) {
      try {
        (*task)(item, thread);
      } catch (...) {
        const std::lock_guard lock(mutex_);
        if (!failure_) failure_ = std::current_exception();
        failed_ = true;
      }
    }
    done_.fetch_add(end - first, std::memory_order_acq_rel);
    next = next_.load(std::memory_order_acquire);
  }
}

inline void WorkerPool::run(std::size_t count, const std::function<void(std::size_t, unsigned)>& task) {
  if (workers_.empty() || count <= 1 || count >= worker_pool_detail::kClosed) {
    for (std::size_t i = 0; i < count; ++i) task(i, 0);
    return;
  }
  // The previous batch is over: every item done. Close it before its task and count change, so that a
  // thread still holding its counter cannot take an item of it under the new count: its compare-and-swap
  // fails on the closed value, which no count reaches.
  next_.store(next_.load(std::memory_order_relaxed) | worker_pool_detail::kClosed, std::memory_order_release);
  task_.store(&task, std::memory_order_release);
  count_.store(count, std::memory_order_release);
  done_.store(0, std::memory_order_release);
  publish((static_cast<std::uint64_t>(worker_pool_detail::batch_of(next_.load()) + 1)) << 32);
  take_items(0);
  // Only items other threads are running are left: wait for them, yielding if that takes long.
  for (int spins = 0; done_.load(std::memory_order_acquire) != count; ++spins) {
    if (spins < 4096)
      worker_pool_detail::pause_briefly();
    else
      std::this_thread::yield();
  }
  if (failed_) {
    failed_ = false;
    const std::exception_ptr failure = failure_;
    failure_ = nullptr;
    std::rethrow_exception(failure);
  }
}

inline void WorkerPool::work(unsigned thread) {
  std::uint32_t seen = 0;  // batch 0 is none; the first batch may have started before this thread did
  while (true) {
    const auto spin_until = std::chrono::steady_clock::now() + worker_pool_detail::kSpinTime;
    for (int spins = 0; worker_pool_detail::batch_of(next_.load(std::memory_order_acquire)) == seen; ++spins) {
      if ((spins & 63) != 63 || std::chrono::steady_clock::now() < spin_until) {
        worker_pool_detail::pause_briefly();
        continue;
      }
      // wait_for rather than wait: GCC 12 exports condition_variable::wait under a symbol version newer
      // than manylinux_2_34 allows, while the timed wait is inline (pthread_cond_clockwait).
      std::unique_lock lock(mutex_);
      while (worker_pool_detail::batch_of(next_.load(std::memory_order_acquire)) == seen)
        wake_.wait_for(lock, std::chrono::milliseconds(100));
    }
    seen = worker_pool_detail::batch_of(next_.load(std::memory_order_acquire));
    if (stopping_) return;
    take_items(thread);
  }
}

}  // namespace exactgeo::detail
