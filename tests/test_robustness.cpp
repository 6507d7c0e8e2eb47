// Junk in, sane answers out: random triangle soups full of what scanned and hand-made meshes contain
// (repeated and coincident vertices, collinear points, flat and zero-area faces, the same face twice in
// either orientation, edges shared by many faces, several pieces) must neither crash, hang nor produce
// NaN, and every distance must still lie between the straight-line distance and the shortest edge path.
// Each soup runs under every variant and pruning-rule combination, with and without welding.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::MeshSoup;
using exactgeo_test::Random;
using exactgeo_test::vertex_count;

constexpr int kSoups = 3000;
constexpr double kSlack = 1e-12;

// A soup of 3 to 40 vertices and up to three faces per vertex. A tenth of the vertices copy an earlier
// vertex's position, a tenth lie on the line through the two before them, a tenth lie in the plane z = 0;
// a tenth of the faces repeat an earlier face reversed; the other faces pick three random vertices (which
// may repeat an index: such faces are dropped by the mesh policy).
MeshSoup junk_soup(Random& random) {
  MeshSoup soup;
  const std::uint32_t vertices = 3 + random.below(38);
  for (std::uint32_t v = 0; v < vertices; ++v) {
    const double kind = random.uniform(0, 1);
    exactgeo_test::Vec3 p;
    if (kind < 0.1 && v > 0) {
      p = exactgeo_test::vertex_position(soup, random.below(v));
    } else if (kind < 0.2 && v > 1) {
      const exactgeo_test::Vec3 a = exactgeo_test::vertex_position(soup, v - 2);
      const exactgeo_test::Vec3 b = exactgeo_test::vertex_position(soup, v - 1);
      const double t = random.uniform(-1, 2);
      for (int k = 0; k < 3; ++k) p[k] = a[k] + t * (b[k] - a[k]);
    } else if (kind < 0.3) {
      p = {random.uniform(-1, 1), random.uniform(-1, 1), 0.0};
    } else {
      p = {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    }
    exactgeo_test::add_vertex(soup, p);
  }
  const std::uint32_t faces = 1 + random.below(3 * vertices);
  for (std::uint32_t f = 0; f < faces; ++f) {
    if (f > 0 && random.uniform(0, 1) < 0.1) {
      const std::uint32_t g = random.below(f);
      exactgeo_test::add_triangle(soup, soup.triangles[3 * g + 2], soup.triangles[3 * g + 1], soup.triangles[3 * g]);
    } else {
      exactgeo_test::add_triangle(soup, random.below(vertices), random.below(vertices), random.below(vertices));
    }
  }
  return soup;
}

// A vertex of the first face that the mesh policy keeps, if any.
std::optional<std::uint32_t> kept_corner(const MeshSoup& soup) {
  for (std::size_t f = 0; f < exactgeo_test::face_count(soup); ++f)
    if (!exactgeo_test::repeats_a_vertex(soup, f)) return soup.triangles[3 * f];
  return std::nullopt;
}

// True if some face through a vertex at v's position has three distinct positions: such a face survives
// welding, so v can be a source of the welded mesh.
bool survives_welding(const MeshSoup& soup, std::uint32_t v) {
  const exactgeo_test::Vec3 p = exactgeo_test::vertex_position(soup, v);
  for (std::size_t f = 0; f < exactgeo_test::face_count(soup); ++f) {
    std::array<exactgeo_test::Vec3, 3> corner;
    for (int k = 0; k < 3; ++k) corner[k] = exactgeo_test::vertex_position(soup, soup.triangles[3 * f + k]);
    const bool distinct = corner[0] != corner[1] && corner[1] != corner[2] && corner[0] != corner[2];
    if (distinct && (corner[0] == p || corner[1] == p || corner[2] == p)) return true;
  }
  return false;
}

class RobustnessUnder : public testing::TestWithParam<exactgeo::GeodesicOptions> {};

INSTANTIATE_TEST_SUITE_P(Robustness, RobustnessUnder, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);
INSTANTIATE_TEST_SUITE_P(RobustnessThreads, RobustnessUnder, testing::ValuesIn(exactgeo_test::kParallelVariants),
                         exactgeo_test::variant_name);

TEST_P(RobustnessUnder, RandomJunkSoupsGiveBoundedDistances) {
  Random random(424242);
  int runs = 0;
  for (int trial = 0; trial < kSoups; ++trial) {
    const MeshSoup soup = junk_soup(random);
    const std::optional<std::uint32_t> source = kept_corner(soup);
    if (!source) continue;
    const auto where = [&](std::uint32_t v) {
      return "soup " + std::to_string(trial) + ", source " + std::to_string(*source) + ", vertex " + std::to_string(v);
    };
    // Edge paths may not pass through a vertex the policy splits into several fans; they bound the distance
    // from above. Without welding, coincident vertices stay apart, so the soup's own edges are the surface's.
    const std::vector<double> upper =
        exactgeo_test::edge_graph_dijkstra(soup, *source, exactgeo_test::non_manifold_vertices(soup));
    const std::vector<double> reachable = exactgeo_test::edge_graph_dijkstra(soup, *source);
    for (const bool weld : {false, true}) {
      std::optional<exactgeo::Mesh> mesh;
      try {
        mesh.emplace(soup, exactgeo::MeshOptions{.weld_duplicate_positions = weld});
      } catch (const exactgeo::Error& error) {
        // Welding can collapse every face that the soup keeps; anything else is a bug.
        ASSERT_TRUE(weld && error.code() == exactgeo::ErrorCode::invalid_mesh) << "soup " << trial << ": " << error.what();
        continue;
      }
      if (weld && !survives_welding(soup, *source)) {
        EXPECT_THROW(exactgeo::geodesic_distance(*mesh, *source, GetParam()), exactgeo::Error) << "soup " << trial;
        continue;
      }
      const exactgeo::GeodesicResult result = exactgeo::geodesic_distance(*mesh, *source, GetParam());
      ++runs;
      ASSERT_EQ(result.distances.size(), vertex_count(soup));
      const double scale = std::max(1.0, exactgeo_test::max_finite(result.distances));
      for (std::uint32_t v = 0; v < vertex_count(soup); ++v) {
        const double d = result.distances[v];
        ASSERT_FALSE(std::isnan(d)) << where(v);
        if (v == *source) {
          ASSERT_EQ(d, 0.0) << where(v);
        }
        if (std::isinf(d)) {
          ASSERT_TRUE(weld || std::isinf(upper[v])) << where(v) << ": unreachable, yet an edge path exists";
          continue;
        }
        ASSERT_GE(d, exactgeo_test::distance_between(soup, *source, v) - kSlack * scale) << where(v);
        if (!weld) {
          ASSERT_FALSE(std::isinf(reachable[v])) << where(v) << ": reached without any edge path";
          ASSERT_LE(d, upper[v] + kSlack * scale) << where(v);
        }
      }
    }
  }
  EXPECT_GT(runs, kSoups);  // most soups keep a face
}

}  // namespace
