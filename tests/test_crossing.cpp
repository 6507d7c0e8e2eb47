// Where the rays of one window end up when it crosses a triangle (src/propagation.cpp, cross_face), and which
// part of the edge opposite a pseudo-source its emission covers (src/shadow_cone.hpp), on generated triangles
// down to near-slivers: the geometry is ill-conditioned there, and what rounding may not do is leave a gap that
// no ray covers. Whether the distances are right on whole meshes is for the oracle, analytic and fuzz tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "exactgeo/mesh.hpp"
#include "propagation.hpp"
#include "shadow_cone.hpp"

namespace {

using exactgeo::detail::CornerDistances;
using exactgeo::detail::FaceFrame;
using exactgeo::detail::SideExit;
using exactgeo::detail::Tolerances;
using exactgeo::detail::Window;

// A number spread evenly in log scale over [10^low, 10^high].
double log_uniform(std::mt19937_64& random, double low, double high) {
  return std::pow(10.0, std::uniform_real_distribution<double>(low, high)(random));
}

// A window over the whole of AB whose pseudo-source lies `height` below it, down to a hair (the corner of a
// near-sliver a source lies on): the ray through the split point runs through C, so the piece that leaves
// through AC ends at C and the piece that leaves through BC starts there. Computed, that ray met BC 1e-5 of
// its length short of C at a height of 6e-13, and the rays in between reached nothing (a distance 3.5e-7 too
// long on a field of near-slivers, tests/test_fuzz.cpp).
TEST(Crossing, ThePiecesEitherSideOfTheSplitPointMeetAtTheApex) {
  std::mt19937_64 random(20291);
  const Tolerances tolerances{1e-12, 1e-13, 1e-15, 1e-6};
  const CornerDistances far{HUGE_VAL, HUGE_VAL, HUGE_VAL};  // no vertex beats the window anywhere
  for (int trial = 0; trial < 20000; ++trial) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double length = 1, apex_x = -0.5 + 2 * unit(random), apex_y = log_uniform(random, -3, 0.5);
    const FaceFrame frame{length, apex_x, apex_y, std::hypot(apex_x, apex_y), std::hypot(length - apex_x, apex_y)};
    const double height = log_uniform(random, -15, 0);
    const Window w{0, length, 0.05 + 0.9 * unit(random), -height, 0, 0};
    std::vector<double> splits;
    const auto reach = exactgeo::detail::reach_apex(std::span(&w, 1), frame, splits, tolerances.prune);
    if (!(splits[0] - w.b0 > tolerances.min_width && w.b1 - splits[0] > tolerances.min_width)) continue;
    std::vector<Window> to_ac, to_bc;
    exactgeo::detail::cross_face(std::span(&w, 1), splits, frame, reach, false, far, SideExit{true, false},
                                 SideExit{true, false}, tolerances, to_ac, to_bc);
    ASSERT_EQ(to_ac.size(), 1u);
    ASSERT_EQ(to_bc.size(), 1u);
    // Both frames run from the side's end on AB (A, B): C is at the side's length.
    EXPECT_EQ(to_ac[0].b1, frame.length_ac) << "trial " << trial << ", height " << height;
    EXPECT_EQ(to_bc[0].b1, frame.length_bc) << "trial " << trial << ", height " << height;
  }
}

// A cone that holds the whole of a corner (a source, a vertex that emits everywhere) covers the whole opposite
// edge, exactly, also at a near-sliver's corner of almost pi, whose neighbours' corners are so thin that an
// ulp of the fan angle there was 1e-4 of the edge.
TEST(Crossing, AConeHoldingAWholeCornerCoversTheWholeOppositeEdge) {
  std::mt19937_64 random(20292);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    // A fan around vertex 0, one of whose triangles is a near-sliver with vertex 0 a hair off its long side.
    const double lift = log_uniform(random, -11, -1);
    const double along = 0.05 + 0.9 * unit(random);
    const exactgeo::MeshSoup soup{{along, lift, 0, 0, 0, 0, 1, 0, 0, along, 1, 0.2 * unit(random)},
                                  {0, 1, 2, 0, 2, 3, 0, 3, 1}};
    const exactgeo::Mesh mesh(soup);
    const exactgeo::detail::SurfaceMesh& surface = mesh.surface();
    const auto everything = exactgeo::detail::ShadowCone::everything();
    for (std::uint32_t c = 0; c < surface.corner_vertex.size(); ++c) {
      const auto [b0, b1] = everything.part_of_opposite_edge(surface, c);
      EXPECT_EQ(b0, 0) << "trial " << trial << ", lift " << lift << ", corner " << c;
      EXPECT_EQ(b1, surface.halfedges[exactgeo::detail::next_halfedge(c)].length)
          << "trial " << trial << ", lift " << lift << ", corner " << c;
    }
  }
}

}  // namespace
