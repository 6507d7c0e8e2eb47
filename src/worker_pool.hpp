// A small fork-join team of threads for the parallel single-source propagation: the engine hands it a batch
// hundreds of times per run (one item per thread for each band of the wavefront, some hundred microseconds
// of work), so the workers spin briefly between batches before they sleep (a wake-up from sleep takes about
// as long as a batch). The caller works on the batch too and waits only for items other threads have taken.
//
// Each thread has a home share of every batch, the same contiguous part of the items each time, and takes
// items from other shares only once its own is done: with one item per thread, each thread runs its own.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <pthread.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace exactgeo::detail {

// A joinable thread on a stack of kWorkerStackBytes instead of the system's default (8 MB on Linux): what
// the engine's threads run needs little stack, and under an address-space limit (common on clusters) the
// default stacks of a few dozen threads would take the room the run needs. Throws std::system_error if the
// system will not start it. Joined when destroyed.
class WorkerThread {
 public:
  static constexpr std::size_t kWorkerStackBytes = std::size_t{1} << 20;

  template <class Body>
  explicit WorkerThread(Body&& body) {
#if defined(__unix__) || defined(__APPLE__)
    auto* owned = new std::function<void()>(std::forward<Body>(body));
    pthread_attr_t attributes;
    pthread_attr_init(&attributes);
    pthread_attr_setstacksize(&attributes, kWorkerStackBytes);
    const int error = pthread_create(&handle_, &attributes, &run, owned);
    pthread_attr_destroy(&attributes);
    if (error != 0) {
      delete owned;
      throw std::system_error(error, std::generic_category(), "cannot start a thread");
    }
#else
    thread_ = std::thread(std::forward<Body>(body));
#endif
  }
  ~WorkerThread() {
#if defined(__unix__) || defined(__APPLE__)
    pthread_join(handle_, nullptr);
#else
    thread_.join();
#endif
  }
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

 private:
#if defined(__unix__) || defined(__APPLE__)
  static void* run(void* body) {
    const std::unique_ptr<std::function<void()>> owned(static_cast<std::function<void()>*>(body));
    (*owned)();
    return nullptr;
  }
  pthread_t handle_;
#else
  std::thread thread_;
#endif
};

// Whether the address space has room for `threads` more threads: each one's stack, and the arena of 64 MB
// glibc's allocator reserves for a thread's allocations (lazily, once the thread runs: so the room for the
// threads started just before is counted too). Under an address-space limit (ulimit -v, common on clusters)
// threads started without that room do start, and then the run fails for want of memory, or glibc aborts
// when a thread cannot get its thread-local data; stopping at the first thread without room leaves the room
// to the run. Probed by reserving it (and giving it back at once): a reservation touches no memory.
inline bool room_for_threads(std::size_t threads) {
#if defined(__linux__)
  const std::size_t room = threads * (std::size_t{96} << 20);
  void* probe = mmap(nullptr, room, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (probe == MAP_FAILED) return false;
  munmap(probe, room);
#endif
  return threads > 0;
}

// The machine's cores (one where their count is unknown), asked once per process: glibc reads a file in /sys
// at every ask, which took longer than the whole build of a two-face mesh (20 of its 25 microseconds).
inline unsigned core_count() {
  static const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return cores;
}

// The thread count a setting asks for: 0 means one per core.
inline unsigned threads_or_cores(unsigned threads) { return threads != 0 ? threads : core_count(); }

// The threads worth starting for `items` items of compute-only work when `asked` for (0: one per core): never
// more than the cores, where a thread beyond them only waits, nor than one per `items_per_thread`, below
// which starting a thread costs more than its share saves.
inline unsigned threads_worth(unsigned asked, std::size_t items, std::size_t items_per_thread) {
  const std::size_t worth = std::max<std::size_t>(1, items / items_per_thread);
  const std::size_t cores = threads_or_cores(0);
  return static_cast<unsigned>(std::min<std::size_t>({threads_or_cores(asked), cores, worth}));
}

class WorkerPool {
 public:
  // `threads` in all, the calling thread included.
  explicit WorkerPool(unsigned threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // The threads in the team: as many as asked for, or fewer if the system would not start them all.
  unsigned threads() const { return static_cast<unsigned>(workers_.size()) + 1; }
  // More threads than cores: a thread that waits should give its core up at once rather than spin.
  bool oversubscribed() const { return spin_time_ == std::chrono::microseconds(0); }

  // Calls task(item, thread) for every item in [0, count), spread over the threads (thread 0 is the
  // caller), and returns when all are done. Which thread runs an item is left to chance: tasks must write
  // only to what their item and their thread own. An exception from a task is rethrown here (the first).
  void run(std::size_t count, const std::function<void(std::size_t, unsigned)>& task);

 private:
  void work(unsigned thread);
  void take_items(unsigned thread, std::uint32_t batch);
  void publish(std::uint32_t batch);

  // A thread's home share of the batch. `next` holds the batch number in its high 32 bits and the next item
  // of the share to take in the low ones. Taking items is a compare-and-swap on it, so a thread that still
  // thinks an older batch is on cannot take anything.
  struct alignas(64) Share {
    std::atomic<std::uint64_t> next{0};
    std::atomic<std::size_t> end{0};
  };

  std::vector<Share> shares_;
  std::chrono::microseconds spin_time_;  // how long a worker spins for the next batch before it sleeps
  std::atomic<std::uint32_t> batch_{0};  // the batch on (0: none yet)
  std::atomic<const std::function<void(std::size_t, unsigned)>*> task_{nullptr};
  std::atomic<std::size_t> done_{0};
  std::atomic<bool> failed_{false};
  std::atomic<bool> stopping_{false};
  std::mutex mutex_;  // for sleeping workers, and the first failure
  std::condition_variable wake_;
  std::exception_ptr failure_;
  std::vector<std::unique_ptr<WorkerThread>> workers_;  // last: they start once everything they read is set
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

}  // namespace worker_pool_detail

// Spins (`spins` times at most), then yields, until `ready` holds.
template <class Ready>
void wait_until(Ready&& ready, int spins = 256) {
  for (int spun = 0; !ready(); ++spun) {
    if (spun < spins)
      worker_pool_detail::pause_briefly();
    else
      std::this_thread::yield();
  }
}

namespace worker_pool_detail {

inline std::uint32_t batch_of(std::uint64_t next) { return static_cast<std::uint32_t>(next >> 32); }

// The item part of a batch's counter once the batch is over: above any item count.
inline constexpr std::uint64_t kClosed = 0xffffffffu;

}  // namespace worker_pool_detail


// With more threads than cores, a spinning worker holds a core that the caller or another worker could use:
// it sleeps at once.
//
// A thread the system will not start, or would start without room to run (a limit on processes or on address
// space, common on clusters; room_for_threads), leaves the team with the threads that did start: every
// thread takes items from every share once its own is done, so the shares of the missing threads are still
// worked off, by the others. threads() says how many there are.
inline WorkerPool::WorkerPool(unsigned threads)
    : shares_(threads),
      spin_time_(threads > core_count() ? std::chrono::microseconds(0) : worker_pool_detail::kSpinTime) {
  try {
    for (unsigned t = 1; t < threads && room_for_threads(t); ++t)
      workers_.push_back(std::make_unique<WorkerThread>([this, t] { work(t); }));
  } catch (const std::system_error&) {
  }
}

inline WorkerPool::~WorkerPool() {
  stopping_ = true;
  publish(batch_.load() + 1);
  workers_.clear();  // joins
}

// Starts a batch (or the shutdown). Stored under the mutex, so that a worker about to sleep either sees it
// or gets the wake-up.
inline void WorkerPool::publish(std::uint32_t batch) {
  {
    const std::lock_guard lock(mutex_);
    batch_.store(batch, std::memory_order_release);
  }
  wake_.notify_all();
}

inline void WorkerPool::take_items(unsigned thread, std::uint32_t batch) {
  const unsigned threads = static_cast<unsigned>(shares_.size());
  const std::function<void(std::size_t, unsigned)>* task = task_.load(std::memory_order_acquire);
  for (unsigned k = 0; k < threads; ++k) {
    Share& share = shares_[(thread + k) % threads];
    std::uint64_t next = share.next.load(std::memory_order_acquire);
    while (true) {
      if (worker_pool_detail::batch_of(next) != batch) return;  // the batch is over
      const std::size_t first = next & 0xffffffffu, end_of_share = share.end.load(std::memory_order_relaxed);
      if (first >= end_of_share) break;
      // Items are taken a few at a time: one shared counter touched per item would cost more than the items
      // on a batch of small ones. About eight takes per share keep the threads' loads even at the end.
      const std::size_t end = std::min(end_of_share, first + std::max<std::size_t>(1, (end_of_share + 7 - first) / 8));
      // Fails if another thread took the items or a new batch began.
      if (!share.next.compare_exchange_weak(next, next + (end - first), std::memory_order_acq_rel)) continue;
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
      next = share.next.load(std::memory_order_acquire);
    }
  }
}

inline void WorkerPool::run(std::size_t count, const std::function<void(std::size_t, unsigned)>& task) {
  if (workers_.empty() || count <= 1 || count >= worker_pool_detail::kClosed) {
    for (std::size_t i = 0; i < count; ++i) task(i, 0);
    return;
  }
  // The previous batch is over: every item done. Its shares are closed before the task and the shares'
  // ends change, so that a thread still holding an old counter cannot take an item under the new ends: its
  // compare-and-swap fails on the closed value, which no end reaches.
  const std::uint32_t batch = batch_.load(std::memory_order_relaxed) + 1;
  const std::size_t threads = shares_.size();
  for (Share& share : shares_)
    share.next.store(share.next.load(std::memory_order_relaxed) | worker_pool_detail::kClosed, std::memory_order_release);
  task_.store(&task, std::memory_order_release);
  done_.store(0, std::memory_order_release);
  for (std::size_t t = 0; t < threads; ++t) {
    shares_[t].end.store(count * (t + 1) / threads, std::memory_order_relaxed);
    shares_[t].next.store((std::uint64_t{batch} << 32) | (count * t / threads), std::memory_order_release);
  }
  publish(batch);
  take_items(0, batch);
  // Only items other threads are running are left: wait for them, yielding if that takes long.
  wait_until([&] { return done_.load(std::memory_order_acquire) == count; }, 4096);
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
    const auto spin_until = std::chrono::steady_clock::now() + spin_time_;
    for (int spins = 0; batch_.load(std::memory_order_acquire) == seen; ++spins) {
      if ((spins & 63) != 63 || std::chrono::steady_clock::now() < spin_until) {
        worker_pool_detail::pause_briefly();
        continue;
      }
      // wait_for rather than wait: GCC 12 exports condition_variable::wait under a symbol version newer
      // than manylinux_2_34 allows, while the timed wait is inline (pthread_cond_clockwait).
      std::unique_lock lock(mutex_);
      while (batch_.load(std::memory_order_acquire) == seen) wake_.wait_for(lock, std::chrono::milliseconds(100));
    }
    seen = batch_.load(std::memory_order_acquire);
    if (stopping_) return;
    take_items(thread, seen);
  }
}

}  // namespace exactgeo::detail
