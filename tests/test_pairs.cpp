// Pair distances (exactgeo::pair_distances): each pair's goal-directed search against a run of the engine
// from the pair's first point with its second as the target (whose exactness the oracle and analytic suites
// establish), under every variant and rule combination, on seeded meshes of many shapes and scales; closed
// forms on flat meshes; +inf between pieces; the same answers on any thread count; paths as long as the
// distances; bad input named. The CGAL oracle's check is in test_pairs_oracle.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::GeodesicOptions;
using exactgeo::Mesh;
using exactgeo::MeshSoup;
using exactgeo::PairOptions;
using exactgeo::SurfacePoint;
using exactgeo_test::Random;

constexpr double kExact = 1e-14;       // relative to the largest distance
constexpr double kPathLength = 1e-9;   // path length against distance, relative (as tests/test_queries.cpp)

struct NamedSoup {
  std::string name;
  MeshSoup soup;
};

MeshSoup scaled(MeshSoup soup, double scale) {
  for (double& x : soup.positions) x *= scale;
  return soup;
}

// Two copies of the soup side by side, sharing nothing: pairs across them are unreachable.
MeshSoup two_pieces(const MeshSoup& soup) {
  MeshSoup both = soup;
  const auto offset = static_cast<std::uint32_t>(exactgeo_test::vertex_count(soup));
  for (std::size_t i = 0; i < soup.positions.size(); ++i) both.positions.push_back(soup.positions[i] + (i % 3 == 0 ? 5.0 : 0.0));
  for (const std::uint32_t v : soup.triangles) both.triangles.push_back(v + offset);
  return both;
}

// Seeded meshes of many shapes: smooth and noisy height fields, a checkerboard (a saddle or a peak at every
// inner vertex), jittered grids with holes, a bumpy torus, a bowtie (a vertex split in three), two pieces,
// and the noisy field at extreme scales.
const std::vector<NamedSoup>& fuzz_meshes() {
  static const std::vector<NamedSoup> all = [] {
    Random random(35);
    std::vector<NamedSoup> list;
    list.push_back({"smooth field", exactgeo_test::random_height_field(random, 9, 8, 0.4, true)});
    const MeshSoup noisy = exactgeo_test::random_height_field(random, 8, 8, 0.15, false);
    list.push_back({"noisy field", noisy});
    list.push_back({"checkerboard", exactgeo_test::checkerboard_height_field(8, 0.1)});
    list.push_back({"grid with holes", exactgeo_test::random_grid_with_holes(random, 10, 9, 3)});
    list.push_back({"bumpy torus", exactgeo::make_bumpy_torus(24, 10)});
    list.push_back({"bowtie", exactgeo_test::random_bowtie(random, 3).soup});
    list.push_back({"two pieces", two_pieces(exactgeo_test::random_height_field(random, 5, 5, 0.3, true))});
    list.push_back({"noisy field at 1e-300", scaled(noisy, 1e-300)});
    list.push_back({"noisy field at 1e300", scaled(noisy, 1e300)});
    return list;
  }();
  return all;
}

// A random point of the mesh: inside a face, on an edge or at a corner.
SurfacePoint random_point(const Mesh& mesh, Random& random) {
  const double u = random.uniform(0, 1), v = random.uniform(0, 1);
  std::array<double, 3> b = {std::min(u, v), std::max(u, v) - std::min(u, v), 1 - std::max(u, v)};
  const std::uint32_t kind = random.below(4);
  if (kind == 1) b = {u, 1 - u, 0};
  if (kind == 2) b = {1, 0, 0};
  std::rotate(b.begin(), b.begin() + random.below(3), b.end());
  return {random.below(mesh.face_count()), b};
}

// Pairs of corners of random faces and of random surface points, and last a pair of one point twice.
struct Pairs {
  std::vector<SurfacePoint> a, b;
};
Pairs random_pairs(const Mesh& mesh, Random& random, std::size_t count) {
  Pairs pairs;
  const auto triangles = mesh.triangles();
  for (std::size_t i = 0; i < count; ++i) {
    if (i % 2 == 0) {
      pairs.a.push_back(exactgeo::vertex_point(mesh, triangles[random.below(triangles.size())]));
      pairs.b.push_back(exactgeo::vertex_point(mesh, triangles[random.below(triangles.size())]));
    } else {
      pairs.a.push_back(random_point(mesh, random));
      pairs.b.push_back(random_point(mesh, random));
    }
  }
  pairs.a.push_back(pairs.a.back());
  pairs.b.push_back(pairs.a.back());
  return pairs;
}

// Each pair as today's targets mode answers it: a run from a[i] that stops once b[i] is final.
std::vector<double> targets_mode(const Mesh& mesh, const Pairs& pairs, const GeodesicOptions& options) {
  exactgeo::GeodesicSolver solver(mesh);
  std::vector<double> distances;
  for (std::size_t i = 0; i < pairs.a.size(); ++i)
    distances.push_back(solver.solve(std::span(&pairs.a[i], 1), std::span(&pairs.b[i], 1), options).target_distances[0]);
  return distances;
}

double path_length(const exactgeo::GeodesicPath& path) {
  double length = 0;
  for (std::size_t k = 1; k < path.points.size(); ++k) length += exactgeo_test::distance(path.points[k - 1], path.points[k]);
  return length;
}

class PairsTest : public testing::TestWithParam<GeodesicOptions> {};
INSTANTIATE_TEST_SUITE_P(Variants, PairsTest, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);

TEST_P(PairsTest, EqualTargetsModeRunsOnGeneratedMeshes) {
  Random random(2016);
  for (const NamedSoup& named : fuzz_meshes()) {
    const Mesh mesh(named.soup);
    const Pairs pairs = random_pairs(mesh, random, 24);
    const auto result = exactgeo::pair_distances(mesh, pairs.a, pairs.b, {.geodesic = GetParam(), .threads = 1});
    const std::vector<double> expected = targets_mode(mesh, pairs, GetParam());
    EXPECT_TRUE(exactgeo_test::distances_match(result.distances, expected, kExact))
        << named.name << ", " << exactgeo_test::variant_label(GetParam());
    EXPECT_EQ(result.distances.back(), 0.0) << named.name << ": a point to itself";
    EXPECT_TRUE(result.paths.empty());
  }
}

// Seeded random meshes, turned at random: smooth and noisy fields, jittered grids with holes, books (non-manifold
// spines cut apart) and sheets with a fin; a failing mesh is named by its seed.
TEST_P(PairsTest, EqualTargetsModeRunsOnSeededRandomMeshes) {
  for (std::uint64_t seed = 1; seed <= 25; ++seed) {
    Random random(seed);
    MeshSoup soup;
    switch (seed % 5) {
      case 0:
      case 1: {
        const int nx = 3 + static_cast<int>(random.below(8)), ny = 3 + static_cast<int>(random.below(8));
        soup = exactgeo_test::random_height_field(random, nx, ny, random.uniform(0.01, 0.8), seed % 5 == 0);
        break;
      }
      case 2: {
        const int nx = 6 + static_cast<int>(random.below(5)), ny = 6 + static_cast<int>(random.below(5));
        soup = exactgeo_test::random_grid_with_holes(random, nx, ny, 1 + static_cast<int>(random.below(3)));
        break;
      }
      case 3:
        soup = exactgeo_test::random_book(random, 3).soup;
        break;
      default:
        soup = exactgeo_test::random_sheet_with_fin(random);
    }
    const Mesh mesh(exactgeo_test::randomly_rotated(std::move(soup), random));
    const Pairs pairs = random_pairs(mesh, random, 8);
    const auto result = exactgeo::pair_distances(mesh, pairs.a, pairs.b, {.geodesic = GetParam(), .threads = 1});
    EXPECT_TRUE(exactgeo_test::distances_match(result.distances, targets_mode(mesh, pairs, GetParam()), kExact))
        << "seed " << seed << ", " << exactgeo_test::variant_label(GetParam());
  }
}

TEST_P(PairsTest, FlatPolygonDistancesAreStraightLines) {
  Random random(77);
  for (int polygon = 0; polygon < 4; ++polygon) {
    const Mesh mesh(exactgeo_test::random_convex_polygon(random, 5 + polygon, 3));
    const Pairs pairs = random_pairs(mesh, random, 30);
    std::vector<double> straight;
    for (std::size_t i = 0; i < pairs.a.size(); ++i)
      straight.push_back(exactgeo_test::distance(exactgeo::point_position(mesh, pairs.a[i]),
                                                 exactgeo::point_position(mesh, pairs.b[i])));
    const auto result = exactgeo::pair_distances(mesh, pairs.a, pairs.b, {.geodesic = GetParam()});
    EXPECT_TRUE(exactgeo_test::distances_match(result.distances, straight, kExact))
        << "polygon " << polygon << ", " << exactgeo_test::variant_label(GetParam());
  }
}

TEST_P(PairsTest, PathsRunFromAToBAndAreAsLongAsTheDistances) {
  Random random(4);
  for (const NamedSoup& named : fuzz_meshes()) {
    const Mesh mesh(named.soup);
    const Pairs pairs = random_pairs(mesh, random, 10);
    const auto result = exactgeo::pair_distances(mesh, pairs.a, pairs.b, {.geodesic = GetParam(), .return_paths = true});
    ASSERT_EQ(result.paths.size(), pairs.a.size());
    const double scale = exactgeo_test::max_finite(result.distances);
    for (std::size_t i = 0; i < pairs.a.size(); ++i) {
      const exactgeo::GeodesicPath& path = result.paths[i];
      if (std::isinf(result.distances[i])) {
        EXPECT_TRUE(path.points.empty()) << named.name << " pair " << i;
        continue;
      }
      ASSERT_FALSE(path.points.empty()) << named.name << " pair " << i;
      EXPECT_EQ(path.source, 0u);
      EXPECT_NEAR(path.length, result.distances[i], kPathLength * scale) << named.name << " pair " << i;
      EXPECT_NEAR(path_length(path), result.distances[i], kPathLength * scale) << named.name << " pair " << i;
      // Traced from b back to a, listed from a: the ends are the pair's points.
      const auto a = exactgeo::point_position(mesh, pairs.a[i]), b = exactgeo::point_position(mesh, pairs.b[i]);
      EXPECT_LE(exactgeo_test::distance(path.points.front(), a), kPathLength * scale) << named.name << " pair " << i;
      EXPECT_LE(exactgeo_test::distance(path.points.back(), b), kPathLength * scale) << named.name << " pair " << i;
    }
  }
}

TEST(Pairs, AnyThreadCountGivesTheSameAnswersBitForBit) {
  Random random(9);
  for (const NamedSoup& named : fuzz_meshes()) {
    const Mesh mesh(named.soup);
    const Pairs pairs = random_pairs(mesh, random, 40);
    const auto one = exactgeo::pair_distances(mesh, pairs.a, pairs.b, {.geodesic = {}, .threads = 1, .return_paths = true});
    for (const unsigned threads : {2u, 3u}) {
      // The search's own thread setting is not used: pairs are spread instead.
      const auto several = exactgeo::pair_distances(
          mesh, pairs.a, pairs.b, {.geodesic = {.threads = 4}, .threads = threads, .return_paths = true});
      EXPECT_EQ(several.distances, one.distances) << named.name << ", " << threads << " threads";
      for (std::size_t i = 0; i < pairs.a.size(); ++i)
        EXPECT_EQ(several.paths[i].points, one.paths[i].points) << named.name << " pair " << i;
    }
  }
}

TEST(Pairs, PiecesApartAreUnreachable) {
  Random random(12);
  const Mesh mesh(two_pieces(exactgeo_test::random_height_field(random, 4, 4, 0.2, false)));
  const auto half = static_cast<std::uint32_t>(mesh.vertex_count() / 2);
  const std::vector<std::uint32_t> a = {0, 3, half + 1, 7};
  const std::vector<std::uint32_t> b = {half + 2, half - 1, 2, 7};
  const auto result = exactgeo::pair_distances(mesh, a, b, {.geodesic = {}, .threads = 0, .return_paths = true});
  EXPECT_TRUE(std::isinf(result.distances[0]) && std::isinf(result.distances[2]));
  EXPECT_TRUE(std::isfinite(result.distances[1]));
  EXPECT_EQ(result.distances[3], 0.0);
  EXPECT_TRUE(result.paths[0].points.empty() && std::isinf(result.paths[0].length));
}

TEST(Pairs, MaxDistanceCutsFartherPairsOffAndKeepsTheOthersExact) {
  Random random(5);
  const Mesh mesh(exactgeo_test::random_height_field(random, 12, 12, 0.3, true));
  const Pairs pairs = random_pairs(mesh, random, 40);
  const auto whole = exactgeo::pair_distances(mesh, pairs.a, pairs.b);
  std::vector<double> sorted = whole.distances;
  std::sort(sorted.begin(), sorted.end());
  const double limit = sorted[sorted.size() / 2];
  const auto cut = exactgeo::pair_distances(mesh, pairs.a, pairs.b, {.geodesic = {.max_distance = limit}});
  std::size_t cut_off = 0;
  for (std::size_t i = 0; i < pairs.a.size(); ++i) {
    if (whole.distances[i] <= limit) {
      EXPECT_EQ(cut.distances[i], whole.distances[i]) << "pair " << i;
    } else {
      EXPECT_TRUE(std::isinf(cut.distances[i])) << "pair " << i;
      ++cut_off;
    }
  }
  EXPECT_GT(cut_off, 0u);
}

TEST(Pairs, VertexPairsEqualTheirPointsAndSplitVerticesTakeTheNearestCopy) {
  Random random(21);
  const exactgeo_test::GluedPieces bowtie = exactgeo_test::random_bowtie(random, 3);
  const Mesh mesh(bowtie.soup);
  std::vector<std::uint32_t> a, b;
  std::vector<SurfacePoint> pa, pb;
  for (std::uint32_t i = 0; i < 20; ++i) {
    a.push_back(bowtie.soup.triangles[random.below(bowtie.soup.triangles.size())]);
    b.push_back(bowtie.soup.triangles[random.below(bowtie.soup.triangles.size())]);
    pa.push_back(exactgeo::vertex_point(mesh, a.back()));
    pb.push_back(exactgeo::vertex_point(mesh, b.back()));
  }
  const auto by_vertex = exactgeo::pair_distances(mesh, a, b);
  EXPECT_EQ(by_vertex.distances, exactgeo::pair_distances(mesh, pa, pb).distances);
  // Against the full distances from each a: the smallest over a split vertex's copies, +inf between wings
  // (a path cannot pass the split vertex from one wing to another).
  std::vector<double> full;
  for (std::size_t i = 0; i < a.size(); ++i) full.push_back(exactgeo::geodesic_distance(mesh, a[i]).distances[b[i]]);
  EXPECT_TRUE(exactgeo_test::distances_match(by_vertex.distances, full, kExact));
}

TEST(Pairs, BadInputIsNamed) {
  const Mesh mesh(exactgeo::make_grid(3, 3, 1.0, 1.0));
  const auto message = [&](auto&& call) {
    try {
      call();
    } catch (const exactgeo::Error& error) {
      EXPECT_EQ(error.code(), exactgeo::ErrorCode::invalid_argument);
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const std::vector<std::uint32_t> two = {0, 1}, one = {2}, out = {0, 99};
  EXPECT_EQ(message([&] { exactgeo::pair_distances(mesh, two, one); }),
            "a and b must have the same length (a has 2 points, b 1)");
  EXPECT_EQ(message([&] { exactgeo::pair_distances(mesh, two, out); }),
            "b 1: vertex 99 is out of range (mesh has 16 vertices)");
  const std::vector<SurfacePoint> points = {{0, {0.2, 0.3, 0.5}}, {40, {1, 0, 0}}};
  EXPECT_EQ(message([&] { exactgeo::pair_distances(mesh, points, points); }),
            "a 1: face 40 is out of range (mesh has 18 faces)");
  EXPECT_NE(message([&] { exactgeo::pair_distances(mesh, two, two, {.geodesic = {.max_distance = -1}}); })
                .find("max_distance"),
            std::string::npos);
  const std::vector<std::uint32_t> none;
  EXPECT_TRUE(exactgeo::pair_distances(mesh, none, none).distances.empty());
}

TEST(Pairs, AStopRequestEndsTheCall) {
  const Mesh mesh(exactgeo::make_bumpy_torus(48, 20));
  std::stop_source stop;
  stop.request_stop();
  const std::vector<std::uint32_t> a = {0, 1}, b = {500, 600};
  try {
    exactgeo::pair_distances(mesh, a, b, {.geodesic = {.stop = stop.get_token()}});
    FAIL() << "not stopped";
  } catch (const exactgeo::Error& error) {
    EXPECT_EQ(error.code(), exactgeo::ErrorCode::cancelled);
  }
}

}  // namespace
