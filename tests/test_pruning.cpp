// Rule 2's pruning of a list (src/propagation.cpp, prune_list) on hand-built windows on one edge: a window
// that loses the whole overlap, and whose rays past it cross the winner's path to the overlap's end on that
// side, is cut past the overlap too; without the crossing, only the overlap is trimmed. The list is walked
// in order of start, so a window meets the windows overlapping it wherever it stood in the list. The edge is
// the x axis, pseudo-sources lie below it. Whether the pruning is sound on whole meshes is for the oracle,
// analytic and metamorphic tests; these check that each rule acts where it should and nowhere else, and
// that what is kept always reaches every point at most as far as the nearest original.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "propagation.hpp"

namespace {

using exactgeo::detail::prune_list;
using exactgeo::detail::Tolerances;
using exactgeo::detail::Window;

constexpr Tolerances kTolerances{1e-12, 1e-12, 1e-15, 1e-6};

Window window(double b0, double b1, double px, double py, double sigma, std::uint32_t source) {
  return {b0, b1, px, py, sigma, source};
}

double distance_at(const Window& w, double x) { return w.sigma + std::hypot(x - w.px, w.py); }

std::vector<Window> pruned(std::vector<Window> windows) {
  windows.resize(prune_list(windows, kTolerances));
  return windows;
}

// v, from a pseudo-source to the right, covers [0.5, 1.5]; w, from a pseudo-source to the left, covers
// [1, 3]. v's path to x = 1.5 meets w's ray to x = 3 behind the edge, at (2, -1/3).
TEST(Pruning, AWindowLosingWhereItsRaysCrossTheWinnersPathGoesWhole) {
  const Window v = window(0.5, 1.5, 3, -1, 0, 1), w = window(1, 3, 0, -1, 1, 2);
  ASSERT_GT(distance_at(w, 1), distance_at(v, 1));  // w loses the overlap [1, 1.5]; trimming alone
  ASSERT_GT(distance_at(w, 1.5), distance_at(v, 1.5));  // would keep its part [1.5, 3] past v's end
  const std::vector<Window> kept = pruned({v, w});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].pseudo_source, 1u);
  EXPECT_EQ(kept[0].b0, v.b0);
  EXPECT_EQ(kept[0].b1, v.b1);
}

TEST(Pruning, WithoutACrossingOnlyTheOverlapIsTrimmed) {
  // The same windows, but w's pseudo-source sits right of v's path: its rays to [1, 3] do not cross it.
  const Window v = window(0.5, 1.5, 3, -1, 0, 1), w = window(1, 3, 3.5, -0.5, 0, 2);
  ASSERT_GT(distance_at(w, 1), distance_at(v, 1));
  ASSERT_GT(distance_at(w, 1.5), distance_at(v, 1.5));  // v wins the whole overlap [1, 1.5]
  const std::vector<Window> kept = pruned({v, w});
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].b1, v.b1);
  EXPECT_DOUBLE_EQ(kept[1].b0, 1.5);  // w keeps what lies past v
  EXPECT_EQ(kept[1].b1, w.b1);
}

TEST(Pruning, TheLoserAtTheOverlapsEndIsCutOnTheFarSideToo) {
  // Now v loses at x = 1, w's start: v's rays to [0.5, 1] cross w's path to x = 1, at (0.857, -0.143) for
  // the ray to 0.5. Trimming alone would leave v its part [0.5, 1] outside w.
  const Window v = window(0.5, 1.5, 3, -1, 0.1, 1), w = window(1, 3, 0, -1, 0, 2);
  ASSERT_GT(distance_at(v, 1), distance_at(w, 1));
  ASSERT_GT(distance_at(v, 1.5), distance_at(w, 1.5));
  const std::vector<Window> kept = pruned({v, w});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].pseudo_source, 2u);
  EXPECT_EQ(kept[0].b0, w.b0);
  EXPECT_EQ(kept[0].b1, w.b1);
}

TEST(Pruning, WithoutACrossingTheLoserKeepsItsPartOutsideTheOverlap) {
  // v's pseudo-source above the line of w's path to x = 1: its rays to [0.5, 1] stay left of that path.
  const Window v = window(0.5, 1.5, 0.2, -0.5, 0.6, 1), w = window(1, 3, 0, -1, 0, 2);
  ASSERT_GT(distance_at(v, 1), distance_at(w, 1));
  ASSERT_GT(distance_at(v, 1.5), distance_at(w, 1.5));
  const std::vector<Window> kept = pruned({v, w});
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].b0, v.b0);
  EXPECT_DOUBLE_EQ(kept[0].b1, 1.0);
  EXPECT_EQ(kept[1].b0, w.b0);
}

// A window beaten everywhere by a window it does not stand next to in the list: the walk takes the windows
// in order of start, where the two meet. (Arrivals from the two other edges of a face join a list one run
// after the other, so windows overlapping on the edge often stand apart in it.)
TEST(Pruning, AWindowBeatenByOneItDoesNotStandNextToGoes) {
  const Window near = window(0, 4, 2, -1, 0, 1);   // the nearest everywhere on [0, 4]
  const Window far = window(3, 5, 4, -1, 2, 2);  // overlaps `near` on [3, 4] only, and loses there
  const Window beaten = window(1, 2, 1.5, -1, 3, 3);
  ASSERT_GT(distance_at(beaten, 1), distance_at(near, 1) + 1);
  ASSERT_GT(distance_at(beaten, 2), distance_at(near, 2) + 1);
  ASSERT_GT(distance_at(far, 3), distance_at(near, 3));
  ASSERT_GT(distance_at(far, 4), distance_at(near, 4));
  const std::vector<Window> kept = pruned({near, far, beaten});
  for (const Window& w : kept) EXPECT_NE(w.pseudo_source, 3u);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].pseudo_source, 1u);  // in order of start
  EXPECT_EQ(kept[1].pseudo_source, 2u);
  EXPECT_DOUBLE_EQ(kept[1].b0, 4.0);  // `far` keeps what lies past `near`
}

// Where the two distances cross inside the overlap, each window is the nearer on one side; unless their
// pseudo-sources' distances are equal (see below), both stay whole.
TEST(Pruning, WindowsWhoseDistancesCrossBothStayWhole) {
  const Window first = window(0, 2, 0.5, -1, 0, 1), second = window(1, 3, 2.5, -1, 0.1, 2);
  ASSERT_LT(distance_at(first, 1), distance_at(second, 1));
  ASSERT_GT(distance_at(first, 2), distance_at(second, 2));
  const std::vector<Window> kept = pruned({second, first});
  ASSERT_EQ(kept.size(), 2u);
  for (const Window* original : {&first, &second}) {
    const Window& w = kept[original->pseudo_source - 1];  // in order of start
    EXPECT_TRUE(w.b0 == original->b0 && w.b1 == original->b1) << "window " << original->pseudo_source;
  }
}

// Two windows of one pseudo-source's distance (two unfoldings of the same source, sigma equal) meet where the
// perpendicular bisector of their pseudo-sources crosses the edge: each window must keep exactly its side
// of the bisector, on seeded random pairs, given in either order.
TEST(Pruning, TwoUnfoldingsOfOneSourceMeetAtTheirBisector) {
  std::mt19937_64 random(20261124);
  std::uniform_real_distribution<double> uniform(0, 1);
  int pairs = 0;
  while (pairs < 500) {
    // first covers [0, 2], second [1, 3]: they overlap on [1, 2], and meet at `meet` inside it.
    const double meet = 1.1 + 0.8 * uniform(random);
    const double a = -3 + 6 * uniform(random), h1 = 0.1 + 5 * uniform(random), h2 = 0.1 + 5 * uniform(random);
    const double squared = (meet - a) * (meet - a) + h1 * h1 - h2 * h2;
    if (squared <= 0.01) continue;
    const double b = meet + (uniform(random) < 0.5 ? -1 : 1) * std::sqrt(squared);
    Window first = window(0, 2, a, -h1, 1, 1), second = window(1, 3, b, -h2, 1, 2);
    // Trimming cuts only the ends of a window that lie inside the overlap: the first must win its left part.
    if (distance_at(first, 1) > distance_at(second, 1)) std::swap(first.px, second.px), std::swap(first.py, second.py);
    if (std::abs(distance_at(first, 1) - distance_at(second, 1)) < 1e-6 ||
        std::abs(distance_at(first, 2) - distance_at(second, 2)) < 1e-6)
      continue;  // too flat for the check below to mean anything
    ++pairs;
    const std::vector<Window> kept = pairs % 2 == 0 ? pruned({first, second}) : pruned({second, first});
    ASSERT_EQ(kept.size(), 2u) << "pair " << pairs;
    EXPECT_NEAR(kept[0].b1, meet, 1e-9) << "pair " << pairs;
    EXPECT_NEAR(kept[1].b0, meet, 1e-9) << "pair " << pairs;
  }
}

// Soundness on seeded random pairs of unrelated windows (different pseudo-sources and distances)
// overlapping on [1, 2], given in either order: wherever the originals reach inside the overlap, the windows
// kept reach too, at most as far as the nearer original, and each kept window is a part of its original.
// (Past the overlap, a loser's rays may go because they cross the winner's path behind the edge: that is
// for the pair tests above.)
TEST(Pruning, WhatIsKeptReachesTheOverlapAsNearAsTheNearerOriginal) {
  std::mt19937_64 random(20261125);
  std::uniform_real_distribution<double> uniform(0, 1);
  int pruned_pairs = 0;
  for (int pair = 0; pair < 5000; ++pair) {
    const Window first = window(0, 2, -3 + 9 * uniform(random), -0.1 - 5 * uniform(random), 2 * uniform(random), 1);
    const Window second = window(1, 3, -3 + 9 * uniform(random), -0.1 - 5 * uniform(random), 2 * uniform(random), 2);
    const std::vector<Window> kept = pair % 2 == 0 ? pruned({first, second}) : pruned({second, first});
    bool changed = kept.size() < 2;
    for (const Window& w : kept) {
      const Window& original = w.pseudo_source == 1 ? first : second;
      EXPECT_TRUE(w.b0 >= original.b0 && w.b1 <= original.b1 && w.px == original.px && w.py == original.py &&
                  w.sigma == original.sigma)
          << "pair " << pair;
      changed |= w.b0 != original.b0 || w.b1 != original.b1;
    }
    pruned_pairs += changed;
    for (int i = 0; i <= 1000; ++i) {
      const double x = 1 + i / 1000.0;
      const double nearest = std::min(distance_at(first, x), distance_at(second, x));
      double reached = HUGE_VAL;
      for (const Window& w : kept)
        if (x >= w.b0 - 1e-9 && x <= w.b1 + 1e-9) reached = std::min(reached, distance_at(w, x));
      ASSERT_LE(reached, nearest + 1e-9) << "pair " << pair << " at x = " << x;
    }
  }
  EXPECT_GT(pruned_pairs, 1000);  // the generator does produce pairs that prune
}

}  // namespace
