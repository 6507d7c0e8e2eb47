// The parallel propagation's two queues on their own (src/band_queue.hpp, src/crossing_queues.hpp): which
// band's vertices come next, and how lists move between threads until a band is over.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <numeric>
#include <thread>
#include <vector>

#include "band_queue.hpp"
#include "crossing_queues.hpp"

namespace exactgeo::detail {
namespace {

// A band queue over vertices with the given distances, all queued.
struct Bands {
  std::vector<double> distance;
  std::vector<bool> queued;
  unsigned threads;
  BandQueue queue;

  Bands(std::vector<double> distances, unsigned thread_count, double width)
      : distance(std::move(distances)), queued(distance.size(), true), threads(thread_count) {
    queue.start(distance.size(), threads, width);
    queue.clear_vertices(0, distance.size());
  }
  void file(std::uint32_t v, double d, unsigned thread = 0) {
    distance[v] = d;
    queue.file(v, d, thread);
  }
  // Starts the next band: false once the queue is empty.
  bool start_next() {
    return queue.next_band([&](std::uint32_t v) { return bool(queued[v]); },
                           [&](std::uint32_t v) { return distance[v]; });
  }
  // The band under way's vertices, taken share by share, each share by its own thread (moved inside: no longer
  // queued).
  std::vector<std::uint32_t> take_band() {
    std::vector<std::uint32_t> taken;
    for (unsigned share = 0; share < threads; ++share)
      queue.take_share(share, [&](std::uint32_t v) {
        if (!queue.take(v, queued[v], distance[v], share)) return;
        taken.push_back(v);
        queued[v] = false;
      });
    return taken;
  }
  // The next band's vertices, in the order the queue gives them; empty once the queue is.
  std::vector<std::uint32_t> next() { return start_next() ? take_band() : std::vector<std::uint32_t>{}; }
};

TEST(BandQueue, GivesTheNearestBandFirstEachVertexInTheBandOfItsDistance) {
  Bands bands({0, 0, 0, 0, 0}, 2, 1.0);
  bands.file(0, 2.5);
  bands.file(1, 0.0);
  bands.file(2, 2.1, 1);
  bands.file(3, 0.99, 1);
  bands.file(4, 7.0);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{1, 3}));  // [0, 1): thread 0's lists, then thread 1's
  EXPECT_EQ(bands.queue.band_under_way(), 1u);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{0, 2}));  // [2, 3): band 2, [1, 2), held none
  EXPECT_EQ(bands.queue.band_under_way(), 3u);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{4}));
  EXPECT_TRUE(bands.next().empty());
}

TEST(BandQueue, OnlyTheLastFilingOfAVertexCounts) {
  Bands bands({0, 0, 0}, 2, 1.0);
  bands.file(0, 5.5);
  bands.file(1, 5.2);
  bands.file(0, 1.5, 1);  // lowered, by another thread: the entry in band 6 is stale
  bands.file(2, 3.0);
  bands.queued[2] = false;  // moved inside some other way: skipped
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{1}));
  EXPECT_TRUE(bands.next().empty());
}

TEST(BandQueue, AVertexAtOrBehindTheBandUnderWayGoesIntoTheNextBand) {
  Bands bands({0, 0, 0}, 1, 1.0);
  bands.file(0, 3.5);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{0}));
  ASSERT_EQ(bands.queue.band_under_way(), 4u);
  bands.file(1, 3.2);  // in the band under way
  bands.file(2, 0.5);  // behind it
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(bands.queue.band_under_way(), 5u);
}

// A thread lowers a vertex of the band under way before its share is taken: it stays in the band (as the
// sequential engine would pop it next), however near it now lies; a vertex behind that was not in the band
// goes into the next.
TEST(BandQueue, AVertexOfTheBandUnderWayLoweredBeforeItIsTakenStaysInIt) {
  Bands bands({0, 0, 0}, 2, 1.0);
  bands.file(0, 3.5, 1);
  bands.file(1, 6.5, 1);
  ASSERT_TRUE(bands.start_next());
  ASSERT_EQ(bands.queue.band_under_way(), 4u);
  bands.file(0, 0.5);  // by thread 0, before thread 1's share is taken
  bands.file(1, 3.1);
  bands.file(2, 3.9, 1);
  EXPECT_EQ(bands.take_band(), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{1, 2}));  // band 5: thread 0's lists, then thread 1's
  EXPECT_EQ(bands.queue.band_under_way(), 5u);
  EXPECT_TRUE(bands.next().empty());
}

// A band whose vertices all left it (filed again, or moved inside) is passed over, not started.
TEST(BandQueue, ABandWithNoVertexToTakeIsPassedOver) {
  Bands bands({0, 0, 0}, 2, 1.0);
  bands.file(0, 1.5);
  bands.file(1, 1.7, 1);
  bands.file(2, 4.5, 1);
  bands.file(1, 0.5);  // band 1 now: its entry in band 2 is stale
  ASSERT_TRUE(bands.start_next());
  EXPECT_EQ(bands.take_band(), (std::vector<std::uint32_t>{1}));
  bands.queued[0] = false;  // moved inside some other way
  ASSERT_TRUE(bands.start_next());
  EXPECT_EQ(bands.queue.band_under_way(), 5u);
  EXPECT_EQ(bands.take_band(), (std::vector<std::uint32_t>{2}));
  EXPECT_FALSE(bands.start_next());
}

TEST(BandQueue, VerticesBeyondTheSlotsWaitInTheLastAndComeInTheirOwnBand) {
  const double far = 3.5 * BandQueue::kSlots;  // more than all the slots ahead
  Bands bands({0, 0, 0}, 2, 1.0);
  bands.file(0, far);
  bands.file(1, far + 0.25, 1);
  bands.file(2, 10.5);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{2}));
  // Filed again as their turn in the last slot came, until their own band: both come together, in it.
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(static_cast<double>(bands.queue.band_under_way()), bands.queue.band_of_distance(far));
  EXPECT_TRUE(bands.next().empty());
}

TEST(BandQueue, AStartAfterARunForgetsItsVertices) {
  Bands bands({0, 0}, 1, 0.5);
  bands.file(0, 0.7);
  bands.file(1, 0.2);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{1}));
  bands.queue.start(2, 1, 0.5);
  bands.queue.clear_vertices(0, 2);
  bands.queued = {true, true};
  EXPECT_TRUE(bands.next().empty());
  bands.file(0, 0.2);
  EXPECT_EQ(bands.next(), (std::vector<std::uint32_t>{0}));
}

TEST(CrossingQueues, AThreadCrossesItsOwnListsNewestFirst) {
  CrossingQueues queues(2);
  const std::vector<std::uint32_t> first = {7, 8};
  queues.start_band(first);
  ASSERT_TRUE(queues.join());
  ASSERT_TRUE(queues.claim_share(0, 0));
  queues.push(0, 9);
  std::vector<std::uint32_t> popped;
  for (std::uint32_t list; queues.pop(0, list);) popped.push_back(list);
  EXPECT_EQ(popped, (std::vector<std::uint32_t>{9, 8, 7}));
  std::uint32_t list;
  EXPECT_FALSE(queues.pop(1, list));
}

TEST(CrossingQueues, EachShareOfVerticesIsClaimedOncePerBand) {
  CrossingQueues queues(3);
  queues.start_band({});
  EXPECT_TRUE(queues.claim_share(1, 0));
  EXPECT_FALSE(queues.claim_share(1, 2));
  EXPECT_TRUE(queues.claim_share(0, 2));
  queues.start_band({});
  EXPECT_TRUE(queues.claim_share(1, 1));
}

// Thread 0 may start late: whoever claims share 0 crosses the band's first lists, so none is left behind.
TEST(CrossingQueues, TheBandsFirstListsGoToTheThreadThatClaimsShareZero) {
  CrossingQueues queues(2);
  const std::vector<std::uint32_t> first = {5, 6};
  queues.start_band(first);
  ASSERT_TRUE(queues.join());  // thread 1, alone so far
  ASSERT_TRUE(queues.claim_share(1, 1));
  ASSERT_TRUE(queues.claim_share(0, 1));
  std::vector<std::uint32_t> popped;
  for (std::uint32_t list; queues.pop(1, list);) popped.push_back(list);
  EXPECT_EQ(popped, (std::vector<std::uint32_t>{6, 5}));
  EXPECT_FALSE(queues.wait_for_lists(1, 0));
  EXPECT_FALSE(queues.join());  // thread 0, too late: nothing was left for it
}

TEST(CrossingQueues, TheBandIsOverWhenEveryThreadThatJoinedIsHungry) {
  CrossingQueues queues(4);
  queues.start_band({});
  ASSERT_TRUE(queues.join());
  EXPECT_FALSE(queues.wait_for_lists(0, 0));  // the only one that joined: the band is over
  EXPECT_FALSE(queues.join());                // a thread started late takes no part
  queues.start_band({});
  EXPECT_TRUE(queues.join());
}

TEST(CrossingQueues, AHungryThreadGetsTheOlderHalfOfAnothersLists) {
  CrossingQueues queues(2);
  queues.start_band({});
  ASSERT_TRUE(queues.join());
  ASSERT_TRUE(queues.join());
  for (std::uint32_t list = 0; list < 10; ++list) queues.push(0, list);
  std::vector<std::uint32_t> fed;
  std::atomic<bool> was_fed{false}, done_feeding{false};
  std::thread hungry([&] {
    EXPECT_TRUE(queues.wait_for_lists(1, 0));
    was_fed = true;
    for (std::uint32_t list; queues.pop(1, list);) fed.push_back(list);
    while (!done_feeding) std::this_thread::yield();  // hungry again only once thread 0 has stopped feeding
    EXPECT_FALSE(queues.wait_for_lists(1, 0));  // over once thread 0 is hungry too
  });
  // A waiting thread is counted hungry before its own flag says so, and feed_hungry passes it over until then;
  // the engine offers again after every crossing, and so does this loop until the thread has been fed.
  while (!was_fed) {
    queues.feed_hungry(0);
    std::this_thread::yield();
  }
  done_feeding = true;
  std::vector<std::uint32_t> kept;
  for (std::uint32_t list; queues.pop(0, list);) kept.push_back(list);
  EXPECT_FALSE(queues.wait_for_lists(0, 0));
  hungry.join();
  EXPECT_EQ(fed, (std::vector<std::uint32_t>{4, 3, 2, 1, 0}));
  EXPECT_EQ(kept, (std::vector<std::uint32_t>{9, 8, 7, 6, 5}));
}

TEST(CrossingQueues, AnAbortEndsEveryWait) {
  CrossingQueues queues(2);
  queues.start_band({});
  ASSERT_TRUE(queues.join());
  ASSERT_TRUE(queues.join());
  std::thread waiting([&] { EXPECT_FALSE(queues.wait_for_lists(1, 0)); });
  queues.abort();  // thread 0 is not hungry: only the abort ends the wait
  waiting.join();
  EXPECT_TRUE(queues.aborted());
}

// Lists that make more lists, as crossings do: every one is crossed exactly once, on any thread, and every
// thread's part ends only when none is left anywhere.
TEST(CrossingQueues, EveryListIsCrossedOnceAndTheBandEndsWhenNoneIsLeft) {
  constexpr unsigned kThreads = 4;
  constexpr std::uint32_t kLists = 20000;  // list i makes lists 2i + 1 and 2i + 2, below kLists
  for (int round = 0; round < 20; ++round) {
    CrossingQueues queues(kThreads);
    const std::vector<std::uint32_t> first = {0};
    queues.start_band(first);  // one share per thread, as the engine's vertices
    std::vector<std::atomic<int>> crossed(kLists);
    std::atomic<std::uint32_t> left_when_done{kLists};
    std::vector<std::thread> threads;
    for (unsigned t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        if (!queues.join()) return;
        for (unsigned k = 0; k < kThreads; ++k) queues.claim_share((t + k) % kThreads, t);
        while (true) {
          std::uint32_t list;
          if (queues.pop(t, list)) {
            crossed[list].fetch_add(1);
            for (std::uint32_t made : {2 * list + 1, 2 * list + 2})
              if (made < kLists) queues.push(t, made);
            if (queues.anyone_hungry()) queues.feed_hungry(t);
            continue;
          }
          if (!queues.wait_for_lists(t, 16)) break;
        }
        std::uint32_t not_crossed = 0;
        for (const std::atomic<int>& c : crossed) not_crossed += c.load() == 0;
        left_when_done.store(std::min(left_when_done.load(), not_crossed));
      });
    }
    for (std::thread& thread : threads) thread.join();
    for (std::uint32_t list = 0; list < kLists; ++list) ASSERT_EQ(crossed[list].load(), 1) << "list " << list;
    EXPECT_EQ(left_when_done.load(), 0u);  // no thread left while lists remained
  }
}

}  // namespace
}  // namespace exactgeo::detail
