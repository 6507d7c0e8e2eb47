// A small fork-join team of threads for the parallel single-source propagation: the engine hands it a batch
// of independent items thousands of times per run, each batch some microseconds of work, so the workers
// spin briefly between batches before they sleep (a wake-up from sleep takes longer than a batch). The
// caller works on the batch too and waits only for items other threads have taken: a worker the system
// does not schedule in time just misses the batch instead of holding it up.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace exactgeo::detail {

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

}  // namespace exactgeo::detail
