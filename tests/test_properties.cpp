// Properties every geodesic distance field has, checked on generated meshes and, where ../shared/meshes is
// present, on the real meshes up to 13K faces (6.5K for the checks that compare several runs): bounds
// (Euclidean <= d <= edge paths), 1-Lipschitz along edges, symmetry, invariance under how the same surface
// is written down, and multi-source = minimum of single sources. Each test runs with the paper's pruning
// rules on and off.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/shapes.hpp"
#include "surface_mesh.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::MeshSoup;
using exactgeo_test::distance_between;
using exactgeo_test::max_finite;
using exactgeo_test::Random;
using exactgeo_test::vertex_count;

// Relative slack of every inequality, as a fraction of the largest distance.
constexpr double kSlack = 1e-12;
// Real meshes up to these sizes keep the suite fast: the first for checks of one run per source, the second
// for checks that compare several runs. The sanitizer build, several times slower, takes the smaller ones:
// the main build checks the rest, and the sanitizers look for memory errors, which the generated meshes and
// the small scans reach as well.
#ifdef EXACTGEO_TESTS_SANITIZED
constexpr std::size_t kMaxSharedFaces = 6'500;
constexpr std::size_t kMaxSharedFacesForComparisons = 2'100;
#else
constexpr std::size_t kMaxSharedFaces = 13'000;
constexpr std::size_t kMaxSharedFacesForComparisons = 6'500;
#endif

struct NamedMesh {
  std::string name;
  MeshSoup soup;
};

// A height field over a grid: open, with boundary, and curved both ways (saddles between the bumps).
MeshSoup bumpy_terrain() {
  MeshSoup soup = exactgeo::make_grid(24, 20, 3.0, 2.5);
  for (std::size_t v = 0; v < vertex_count(soup); ++v) {
    const double x = soup.positions[3 * v], y = soup.positions[3 * v + 1];
    soup.positions[3 * v + 2] = 0.3 * std::sin(3 * x) * std::cos(2 * y) + 0.1 * x * y;
  }
  return soup;
}

// Generated meshes, then the real ones up to kMaxSharedFaces (loaded once).
const std::vector<NamedMesh>& all_meshes() {
  static const std::vector<NamedMesh> all = [] {
    std::vector<NamedMesh> list = {{"bumpy torus", exactgeo::make_bumpy_torus(48, 20)},
                                   {"icosphere", exactgeo::make_icosphere(3)},
                                   {"bumpy terrain", bumpy_terrain()}};
    for (const std::string& name : exactgeo_test::shared_mesh_names()) {
      MeshSoup soup = *exactgeo_test::load_shared_mesh(name);
      if (exactgeo_test::face_count(soup) <= kMaxSharedFaces) list.push_back({name, std::move(soup)});
    }
    return list;
  }();
  return all;
}

// The meshes for checks that compare several runs.
std::vector<const NamedMesh*> comparison_meshes() {
  std::vector<const NamedMesh*> list;
  for (const NamedMesh& m : all_meshes())
    if (exactgeo_test::face_count(m.soup) <= kMaxSharedFacesForComparisons) list.push_back(&m);
  return list;
}

// Two sources per mesh: a random vertex, and a boundary vertex where there is one (else another random one).
std::vector<std::uint32_t> sources_of(const MeshSoup& soup) {
  return {exactgeo_test::random_source_vertex(soup, 1),
          exactgeo_test::first_boundary_vertex(soup).value_or(exactgeo_test::random_source_vertex(soup, 2))};
}

// The same surface written differently: vertices renumbered, faces reordered, each face's corners rotated
// and, for about half of them, reversed. new_index[v] is the new number of input vertex v.
struct Scrambled {
  MeshSoup soup;
  std::vector<std::uint32_t> new_index;
};

Scrambled scrambled(const MeshSoup& soup, std::uint64_t seed) {
  Random random(seed);
  const auto shuffle = [&](auto& items) {
    for (std::size_t i = items.size(); i > 1; --i) std::swap(items[i - 1], items[random.below(i)]);
  };
  Scrambled out;
  out.new_index.resize(vertex_count(soup));
  std::iota(out.new_index.begin(), out.new_index.end(), 0u);
  shuffle(out.new_index);
  out.soup.positions.resize(soup.positions.size());
  for (std::size_t v = 0; v < vertex_count(soup); ++v)
    for (int k = 0; k < 3; ++k) out.soup.positions[3 * out.new_index[v] + k] = soup.positions[3 * v + k];

  std::vector<std::uint32_t> face_order(exactgeo_test::face_count(soup));
  std::iota(face_order.begin(), face_order.end(), 0u);
  shuffle(face_order);
  for (std::uint32_t f : face_order) {
    std::array<std::uint32_t, 3> corner;
    const std::uint32_t rotation = random.below(3);
    for (std::uint32_t k = 0; k < 3; ++k) corner[k] = out.new_index[soup.triangles[3 * f + (k + rotation) % 3]];
    if (random.below(2) == 1) std::swap(corner[1], corner[2]);
    out.soup.triangles.insert(out.soup.triangles.end(), corner.begin(), corner.end());
  }
  return out;
}

class PropertiesOf : public testing::TestWithParam<exactgeo::GeodesicOptions> {
 protected:
  exactgeo::GeodesicResult run(const exactgeo::Mesh& mesh, std::uint32_t source) const {
    return exactgeo::geodesic_distance(mesh, source, GetParam());
  }
};

INSTANTIATE_TEST_SUITE_P(Properties, PropertiesOf, testing::ValuesIn(exactgeo_test::kAllVariants),
                         exactgeo_test::variant_name);
INSTANTIATE_TEST_SUITE_P(PropertiesThreads, PropertiesOf, testing::ValuesIn(exactgeo_test::kParallelVariants),
                         exactgeo_test::variant_name);

TEST(PropertiesMeshes, SharedMeshesAreIncludedWhenPresent) {
  EXACTGEO_SKIP_IF_NO_SHARED_MESHES();
  EXPECT_GT(all_meshes().size(), 3u);
}

// Counts the vertices or edges where a property fails and keeps the first, so a broken property reports
// once per mesh instead of once per vertex.
struct Violations {
  std::size_t count = 0;
  std::string first;
  void add(const std::string& what) {
    if (count++ == 0) first = what;
  }
};

// Euclidean <= d <= shortest edge path; |d(u) - d(v)| <= |uv| along every edge; d(source) = 0; no NaN.
// A geodesic cannot cross a vertex the mesh policy splits from one fan to another, so edge paths may not
// pass through such vertices; and a split vertex's distance is the smallest over its copies, so along an
// edge to it only the bound on its own distance holds.
TEST_P(PropertiesOf, BoundsAndEdgeLipschitz) {
  for (const NamedMesh& m : all_meshes()) {
    const exactgeo::Mesh mesh(m.soup);
    const std::vector<std::uint8_t> split = exactgeo_test::non_manifold_vertices(m.soup);
    for (std::uint32_t source : sources_of(m.soup)) {
      SCOPED_TRACE(m.name + ", source " + std::to_string(source));
      const std::vector<double> d = run(mesh, source).distances;
      ASSERT_EQ(d.size(), vertex_count(m.soup));
      EXPECT_EQ(d[source], 0.0);
      const double tiny = kSlack * max_finite(d);
      ASSERT_GT(tiny, 0.0);
      const std::vector<double> edge_paths = exactgeo_test::edge_graph_dijkstra(m.soup, source, split);
      Violations nan, below_euclidean, above_edge_paths, steeper_than_edge;
      const auto at = [&](std::uint32_t v) { return "vertex " + std::to_string(v) + " at " + std::to_string(d[v]); };
      for (std::uint32_t v = 0; v < d.size(); ++v) {
        if (std::isnan(d[v])) nan.add(at(v));
        if (d[v] < distance_between(m.soup, source, v) - tiny) below_euclidean.add(at(v));
        if (!(d[v] <= edge_paths[v] + tiny)) above_edge_paths.add(at(v) + " > " + std::to_string(edge_paths[v]));
      }
      for (const exactgeo_test::MeshEdge& e : exactgeo_test::unique_edges(m.soup)) {
        const std::uint32_t u = e.low, v = e.high;
        const double length = distance_between(m.soup, u, v) * (1 + kSlack) + tiny;
        if ((!split[v] && !(d[u] <= d[v] + length)) || (!split[u] && !(d[v] <= d[u] + length)))
          steeper_than_edge.add(at(u) + ", " + at(v) + ", edge length " + std::to_string(length));
      }
      EXPECT_EQ(nan.count, 0u) << "NaN at " << nan.first;
      EXPECT_EQ(below_euclidean.count, 0u) << "shorter than the straight line at " << below_euclidean.first;
      EXPECT_EQ(above_edge_paths.count, 0u) << "longer than an edge path at " << above_edge_paths.first;
      EXPECT_EQ(steeper_than_edge.count, 0u) << "differs by more than the edge length at " << steeper_than_edge.first;
    }
  }
}

TEST_P(PropertiesOf, Symmetry) {
  for (const NamedMesh* named : comparison_meshes()) {
    const NamedMesh& m = *named;
    const exactgeo::Mesh mesh(m.soup);
    const std::uint32_t a = exactgeo_test::random_source_vertex(m.soup, 3);
    const std::uint32_t b = exactgeo_test::random_source_vertex(m.soup, 4);
    const std::uint32_t c = exactgeo_test::random_source_vertex(m.soup, 5);
    const std::vector<double> from_a = run(mesh, a).distances;
    const std::vector<double> from_b = run(mesh, b).distances;
    const std::vector<double> from_c = run(mesh, c).distances;
    const double tolerance = kSlack * max_finite(from_a);
    EXPECT_NEAR(from_a[b], from_b[a], tolerance) << m.name << ": " << a << " and " << b;
    EXPECT_NEAR(from_a[c], from_c[a], tolerance) << m.name << ": " << a << " and " << c;
    EXPECT_NEAR(from_b[c], from_c[b], tolerance) << m.name << ": " << b << " and " << c;
  }
}

TEST_P(PropertiesOf, InvariantUnderOrientationCornerOrderAndNumbering) {
  for (const NamedMesh* named : comparison_meshes()) {
    const NamedMesh& m = *named;
    SCOPED_TRACE(m.name);
    const std::uint32_t source = exactgeo_test::random_source_vertex(m.soup, 6);
    const std::vector<double> d = run(exactgeo::Mesh(m.soup), source).distances;
    const Scrambled s = scrambled(m.soup, 7);
    const exactgeo::Mesh scrambled_mesh(s.soup);
    EXPECT_EQ(scrambled_mesh.report().non_manifold_vertices, exactgeo::Mesh(m.soup).report().non_manifold_vertices);
    const std::vector<double> scrambled_d = run(scrambled_mesh, s.new_index[source]).distances;
    std::vector<double> mapped_back(d.size());
    for (std::size_t v = 0; v < d.size(); ++v) mapped_back[v] = scrambled_d[s.new_index[v]];
    EXPECT_TRUE(exactgeo_test::distances_match(mapped_back, d, kSlack));
  }
}

// The engine numbers faces and vertices in spatial order (for its memory traffic), so that a mesh runs as
// fast whatever order its file lists them in: a scrambled copy of a mesh gets the same numbering, seen as
// positions, and neighbours in that numbering lie close together.
TEST(SurfaceNumbering, FollowsSpaceNotTheInputOrder) {
  using exactgeo::detail::SurfaceMesh;
  for (const NamedMesh& m : all_meshes()) {
    SCOPED_TRACE(m.name);
    const MeshSoup scrambled_soup = scrambled(m.soup, 11).soup;
    const exactgeo::Mesh original(m.soup), scrambled_mesh(scrambled_soup);
    const SurfaceMesh &a = original.surface(), &b = scrambled_mesh.surface();
    // Where surface vertex v of a (or b) lies.
    auto position = [&](const SurfaceMesh& s, std::uint32_t v) {
      const MeshSoup& soup = &s == &a ? m.soup : scrambled_soup;
      return exactgeo_test::vertex_position(soup, s.surface_to_input[v]);
    };
    auto corners = [&](const SurfaceMesh& s, std::uint32_t f) {
      std::array<exactgeo_test::Vec3, 3> p;
      for (std::uint32_t k = 0; k < 3; ++k) p[k] = position(s, s.corner_vertex[3 * f + k]);
      std::sort(p.begin(), p.end());
      return p;
    };
    ASSERT_EQ(a.vertex_count, b.vertex_count);
    ASSERT_EQ(a.face_count(), b.face_count());
    for (std::uint32_t v = 0; v < a.vertex_count; ++v) ASSERT_EQ(position(a, v), position(b, v)) << "vertex " << v;
    for (std::uint32_t f = 0; f < a.face_count(); ++f) ASSERT_EQ(corners(a, f), corners(b, f)) << "face " << f;

    // Consecutive vertices of the scrambled copy lie a few edges apart on average (in its input order, about
    // a third of the mesh's size).
    double steps = 0, edges = 0;
    for (std::uint32_t v = 1; v < b.vertex_count; ++v)
      steps += exactgeo_test::distance(position(b, v - 1), position(b, v));
    for (std::uint32_t h = 0; h < b.corner_vertex.size(); ++h) edges += b.halfedges[h].length;
    const double mean_edge = std::ldexp(edges / static_cast<double>(b.corner_vertex.size()), -b.scale_exponent);
    EXPECT_LT(steps / (b.vertex_count - 1), 4 * mean_edge);
  }
}

TEST_P(PropertiesOf, MultiSourceIsTheMinimumOfSingleSources) {
  for (const NamedMesh* named : comparison_meshes()) {
    const NamedMesh& m = *named;
    SCOPED_TRACE(m.name);
    const exactgeo::Mesh mesh(m.soup);
    std::vector<std::uint32_t> sources;
    for (std::uint64_t seed = 8; sources.size() < 3; ++seed) {
      const std::uint32_t v = exactgeo_test::random_source_vertex(m.soup, seed);
      if (std::find(sources.begin(), sources.end(), v) == sources.end()) sources.push_back(v);
    }
    std::vector<std::vector<double>> single;
    for (std::uint32_t s : sources) single.push_back(run(mesh, s).distances);
    const exactgeo::GeodesicResult multi = exactgeo::geodesic_distance(mesh, sources, GetParam());

    std::vector<double> minimum(vertex_count(m.soup), HUGE_VAL);
    for (const auto& d : single)
      for (std::size_t v = 0; v < d.size(); ++v) minimum[v] = std::min(minimum[v], d[v]);
    EXPECT_TRUE(exactgeo_test::distances_match(multi.distances, minimum, kSlack));

    const double tiny = kSlack * max_finite(minimum);
    ASSERT_EQ(multi.nearest_source.size(), vertex_count(m.soup));
    for (std::uint32_t v = 0; v < minimum.size(); ++v) {
      const std::uint32_t nearest = multi.nearest_source[v];
      if (!std::isfinite(minimum[v])) {
        EXPECT_EQ(nearest, exactgeo::kNoSource) << "vertex " << v;
        continue;
      }
      ASSERT_LT(nearest, sources.size()) << "vertex " << v;
      EXPECT_LE(single[nearest][v], minimum[v] + tiny) << "vertex " << v << " names source " << nearest;
    }
    for (std::uint32_t i = 0; i < sources.size(); ++i) {
      EXPECT_EQ(multi.distances[sources[i]], 0.0);
      EXPECT_EQ(multi.nearest_source[sources[i]], i);
    }
  }
}

}  // namespace
