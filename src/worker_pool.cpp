#include "worker_pool.hpp"

#include <algorithm>
#include <chrono>

namespace exactgeo::detail {
namespace {

// How long a worker spins for the next batch before it sleeps: batches follow each other within
// microseconds while a propagation runs; between runs the workers should not burn a core.
constexpr auto kSpinTime = std::chrono::microseconds(200);

void pause_briefly() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

std::uint32_t batch_of(std::uint64_t next) { return static_cast<std::uint32_t>(next >> 32); }

}  // namespace

WorkerPool::WorkerPool(unsigned threads) {
  for (unsigned t = 1; t < threads; ++t) workers_.emplace_back([this, t] { work(t); });
}

WorkerPool::~WorkerPool() {
  stopping_ = true;
  publish(next_.load() + (std::uint64_t{1} << 32));
  workers_.clear();  // joins
}

// Starts a batch (or the shutdown). Stored under the mutex, so that a worker about to sleep either sees it
// or gets the wake-up.
void WorkerPool::publish(std::uint64_t next) {
  {
    const std::lock_guard lock(mutex_);
    next_.store(next, std::memory_order_release);
  }
  wake_.notify_all();
}

void WorkerPool::take_items(unsigned thread) {
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

void WorkerPool::run(std::size_t count, const std::function<void(std::size_t, unsigned)>& task) {
  if (workers_.empty() || count <= 1) {
    for (std::size_t i = 0; i < count; ++i) task(i, 0);
    return;
  }
  // The previous batch is over: every item done, so no thread is inside take_items with it any more except
  // to find it exhausted.
  task_.store(&task, std::memory_order_release);
  count_.store(count, std::memory_order_release);
  done_.store(0, std::memory_order_release);
  publish((static_cast<std::uint64_t>(batch_of(next_.load()) + 1)) << 32);
  take_items(0);
  // Only items other threads are running are left: wait for them, yielding if that takes long.
  for (int spins = 0; done_.load(std::memory_order_acquire) != count; ++spins) {
    if (spins < 4096)
      pause_briefly();
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

void WorkerPool::work(unsigned thread) {
  std::uint32_t seen = 0;  // batch 0 is none; the first batch may have started before this thread did
  while (true) {
    const auto spin_until = std::chrono::steady_clock::now() + kSpinTime;
    for (int spins = 0; batch_of(next_.load(std::memory_order_acquire)) == seen; ++spins) {
      if ((spins & 63) != 63 || std::chrono::steady_clock::now() < spin_until) {
        pause_briefly();
        continue;
      }
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return batch_of(next_.load(std::memory_order_acquire)) != seen; });
    }
    seen = batch_of(next_.load(std::memory_order_acquire));
    if (stopping_) return;
    take_items(thread);
  }
}

}  // namespace exactgeo::detail
