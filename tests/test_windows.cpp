// The window lists (src/windows.hpp): every list keeps exactly its windows through growth, moves, frees and
// reuse, whichever thread changes it, also with several threads changing different lists at once; each
// list's record counts the runs of windows added since it was empty; the count of live windows adds up;
// the order-preserving merge keeps a list ordered by start.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <thread>
#include <vector>

#include "test_meshes.hpp"
#include "windows.hpp"

namespace {

using exactgeo::detail::Window;
using exactgeo::detail::WindowLists;

// A window that names its list and its place in the sequence of windows ever made, so that a window in the
// wrong list or place shows.
Window tagged(std::uint32_t list, std::uint32_t serial) {
  return Window{static_cast<double>(serial), static_cast<double>(serial) + 0.5, static_cast<double>(list), -1, 0, serial};
}

// Clears the records in one part, as a one-thread run does.
void reset_lists(WindowLists& lists, std::size_t count, unsigned threads) {
  lists.reset(count, threads, [](std::size_t n, const auto& clear) { clear(0, n); });
}

// A list's windows and the runs added since it was empty (counted up to 2), as WindowLists should have them.
struct ModelList {
  std::vector<Window> windows;
  std::uint8_t runs = 0;
};

// One step of a seeded random sequence of changes to list h by `thread`, mirrored on `model`.
void change_at_random(WindowLists& lists, std::vector<ModelList>& model, std::uint32_t h, unsigned thread,
                      exactgeo_test::Random& random, std::uint32_t& serial) {
  std::vector<Window>& expected = model[h].windows;
  // Every change below that adds windows adds one run (a list emptied by shrink_to keeps its count).
  const std::uint8_t runs_after_adding = expected.empty() ? 1 : 2;
  // Mostly growth, now and then by a lot (past the largest chunk), so lists move between blocks of all sizes.
  const std::uint32_t count = random.below(50) == 0 ? 1 + random.below(70'000) : 1 + random.below(12);
  std::vector<Window> windows;
  for (std::uint32_t k = 0; k < count; ++k) windows.push_back(tagged(h, serial++));
  switch (random.below(5)) {
    case 0:
      lists.append(h, windows, thread);
      expected.insert(expected.end(), windows.begin(), windows.end());
      model[h].runs = runs_after_adding;
      break;
    case 1:
      lists.prepend(h, windows, thread);
      expected.insert(expected.begin(), windows.begin(), windows.end());
      model[h].runs = runs_after_adding;
      break;
    case 2: {
      const std::span<Window> list = lists.extend(h, windows.size(), thread);
      std::copy(windows.begin(), windows.end(), list.end() - static_cast<std::ptrdiff_t>(windows.size()));
      expected.insert(expected.end(), windows.begin(), windows.end());
      model[h].runs = runs_after_adding;
      const std::size_t kept = random.below(expected.size() + 1);
      lists.shrink_to(h, kept, thread);
      expected.resize(kept);
      break;
    }
    default:
      if (random.below(3) == 0) {
        lists.clear(h, thread);
        expected.clear();
        model[h].runs = 0;
      } else {
        lists.append(h, windows, thread);
        expected.insert(expected.end(), windows.begin(), windows.end());
        model[h].runs = runs_after_adding;
      }
  }
}

bool same_windows(std::span<const Window> a, const std::vector<Window>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const Window& x, const Window& y) {
    return x.b0 == y.b0 && x.b1 == y.b1 && x.px == y.px && x.py == y.py && x.pseudo_source == y.pseudo_source;
  });
}

TEST(WindowLists, EveryListKeepsItsWindowsWhicheverThreadChangesIt) {
  constexpr std::uint32_t kLists = 300;
  constexpr unsigned kThreads = 3;
  WindowLists lists;
  reset_lists(lists, kLists, kThreads);
  std::vector<ModelList> model(kLists);
  exactgeo_test::Random random(11);
  std::uint32_t serial = 0;
  std::size_t peak = 0;
  for (int step = 0; step < 6'000; ++step) {
    const std::uint32_t h = random.below(kLists);
    change_at_random(lists, model, h, random.below(kThreads), random, serial);
    ASSERT_TRUE(same_windows(lists.view(h), model[h].windows)) << "list " << h << " after step " << step;
    ASSERT_EQ(lists.empty(h), model[h].windows.empty());
    ASSERT_EQ(lists.record(h).runs, model[h].runs) << "list " << h << " after step " << step;
    if (step % 100 == 0) {
      // Changing one list leaves the others as they were.
      for (std::uint32_t g = 0; g < kLists; ++g) ASSERT_TRUE(same_windows(lists.view(g), model[g].windows)) << "list " << g;
      std::size_t live = 0;
      for (const ModelList& list : model) live += list.windows.size();
      peak = std::max(peak, live);
      lists.note_peak();
      ASSERT_EQ(lists.peak_live(), peak) << "step " << step;
    }
  }
  EXPECT_GT(lists.arena_bytes(), 70'000 * sizeof(Window));
}

// The parallel rounds' use: several threads change disjoint sets of lists at once, each freeing blocks that
// others carved before. (Run under ThreadSanitizer by `make test-tsan`.)
TEST(WindowLists, ThreadsChangingDifferentListsAtOnceKeepEachListsWindows) {
  constexpr std::uint32_t kLists = 400;
  constexpr unsigned kThreads = 4;
  WindowLists lists;
  reset_lists(lists, kLists, kThreads);
  std::vector<ModelList> model(kLists);
  for (int rounds = 0; rounds < 4; ++rounds) {
    // Round r: thread t owns the lists h with (h + r) % kThreads == t, so ownership moves every round.
    std::vector<std::jthread> team;
    for (unsigned t = 0; t < kThreads; ++t) {
      team.emplace_back([&, t] {
        exactgeo_test::Random random(100 * rounds + t);
        std::uint32_t serial = (t + 1) * 100'000'000u + rounds * 10'000'000u;
        for (int step = 0; step < 1'000; ++step) {
          const std::uint32_t h = kThreads * random.below(kLists / kThreads) + (t + kThreads - rounds % kThreads) % kThreads;
          change_at_random(lists, model, h, t, random, serial);
        }
      });
    }
    team.clear();  // joins
    for (std::uint32_t h = 0; h < kLists; ++h) {
      ASSERT_TRUE(same_windows(lists.view(h), model[h].windows)) << "list " << h;
      ASSERT_EQ(lists.record(h).runs, model[h].runs) << "list " << h;
    }
  }
}

// The parallel bands take a list off its edge to cross it: the record taken says how many runs it held, and
// the edge starts again from none.
TEST(WindowLists, TakingAListTakesItsRunsAndLeavesTheEdgeEmpty) {
  WindowLists lists;
  reset_lists(lists, 2, 1);
  const Window first[] = {tagged(0, 1), tagged(0, 2)}, second[] = {tagged(0, 3)};
  lists.append(0, first, 0);
  EXPECT_EQ(lists.record(0).runs, 1);
  lists.prepend(0, second, 0);
  const WindowLists::List taken = lists.take(0);
  EXPECT_EQ(taken.runs, 2);
  EXPECT_EQ(taken.size, 3u);
  EXPECT_TRUE(lists.empty(0));
  EXPECT_EQ(lists.record(0).runs, 0);
  lists.give_back(taken, 0);
  lists.append(0, second, 0);
  EXPECT_EQ(lists.record(0).runs, 1);
  EXPECT_TRUE(same_windows(lists.view(0), {second[0]}));
}

// A run on several threads clears the records in parts, one per thread: every list starts empty, unmarked
// and without runs, whatever the run before left, also when the next mesh is larger (new records) or
// smaller (the old ones reused).
TEST(WindowLists, ResetInPartsOnSeveralThreadsEmptiesEveryList) {
  WindowLists lists;
  exactgeo_test::Random random(5);
  for (const std::uint32_t count : {50u, 2'000u, 700u, 2'000u}) {
    constexpr unsigned kThreads = 3;
    lists.reset(count, kThreads, [](std::size_t n, const auto& clear) {
      std::vector<std::jthread> team;
      for (unsigned part = kThreads; part-- > 0;) team.emplace_back([&, part] { clear(n * part / kThreads, n * (part + 1) / kThreads); });
    });
    for (std::uint32_t h = 0; h < count; ++h) {
      const WindowLists::List& record = lists.record(h);
      ASSERT_TRUE(record.size == 0 && record.capacity() == 0 && record.runs == 0 && record.scheduled == 0 &&
                  record.depth == 0 && record.data == nullptr)
          << "list " << h << " of " << count;
    }
    // Leave every list holding windows and marks for the next reset to clear.
    std::uint32_t serial = 0;
    for (std::uint32_t h = 0; h < count; ++h) {
      const Window windows[] = {tagged(h, serial++), tagged(h, serial++)};
      lists.append(h, windows, random.below(kThreads));
      lists.record(h).scheduled = 1;
      lists.record(h).depth = 7;
      ASSERT_TRUE(same_windows(lists.view(h), {windows[0], windows[1]})) << "list " << h;
    }
  }
}

// Order-preserving SecondMerge: windows are inserted by the start of their interval.
TEST(WindowLists, InsertInOrderKeepsTheListOrderedByStart) {
  WindowLists lists;
  reset_lists(lists, 2, 1);
  const auto window = [](double b0, std::uint32_t tag) { return Window{b0, b0 + 0.5, 0, -1, 0, tag}; };
  const std::vector<Window> existing = {window(0.0, 0), window(1.0, 1), window(2.0, 2)};
  lists.append(1, existing, 0);
  const std::vector<Window> arriving = {window(2.5, 3), window(-1.0, 4), window(1.0, 5), window(1.5, 6)};
  const std::span<Window> list = lists.extend(1, arriving.size(), 0);
  std::copy(arriving.begin(), arriving.end(), list.end() - static_cast<std::ptrdiff_t>(arriving.size()));
  exactgeo::detail::insert_in_order(list, existing.size());
  std::vector<std::uint32_t> tags;
  for (const Window& w : lists.view(1)) tags.push_back(w.pseudo_source);
  // A window starting where another starts goes after it.
  EXPECT_EQ(tags, (std::vector<std::uint32_t>{4, 0, 1, 5, 6, 2, 3}));
  EXPECT_TRUE(lists.empty(0));
}

}  // namespace
