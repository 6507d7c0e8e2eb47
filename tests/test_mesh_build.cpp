// The parallel mesh build gives the same surface, bit for bit, on any thread count and however its passes
// are cut into ranges: every array of the SurfaceMesh and every count of the report. Checked on generated
// junk (duplicate, repeated and non-manifold faces, bowties, seams, zero-length edges, unreferenced
// vertices), random height fields and grids with holes, and the shared meshes, welded and not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <stop_token>
#include <string>
#include <vector>

#include "exactgeo/error.hpp"
#include "exactgeo/io.hpp"
#include "exactgeo/mesh.hpp"
#include "mesh_build.hpp"
#include "test_meshes.hpp"

namespace {

using exactgeo::MeshSoup;
using exactgeo::detail::SurfaceMesh;
using exactgeo_test::add_triangle;
using exactgeo_test::add_vertex;
using exactgeo_test::Random;

std::shared_ptr<const SurfaceMesh> build(const MeshSoup& soup, bool weld, unsigned threads, std::size_t grain) {
  return exactgeo::detail::build_surface(std::vector<double>(soup.positions), std::vector<std::uint32_t>(soup.triangles),
                                         {.weld_duplicate_positions = weld}, threads, grain);
}

// Doubles compared by their bits: -0 and 0, or two NaNs, must not pass for one another.
bool same_bits(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

testing::AssertionResult same_surface(const SurfaceMesh& a, const SurfaceMesh& b) {
  std::string differs;
  const auto check = [&](bool same, const char* what) {
    if (!same) differs += std::string(differs.empty() ? "" : ", ") + what;
  };
  exactgeo::for_each_report_field([&](const char* name, auto member, const char*) {
    check(a.report.*member == b.report.*member, name);
  });
  check(a.scale_exponent == b.scale_exponent, "scale_exponent");
  check(a.vertex_count == b.vertex_count, "vertex_count");
  check(a.surface_to_input == b.surface_to_input, "surface_to_input");
  check(a.input_copies_offsets == b.input_copies_offsets, "input_copies_offsets");
  check(a.input_copies == b.input_copies, "input_copies");
  check(a.canonical_input == b.canonical_input, "canonical_input");
  check(a.input_face_to_surface == b.input_face_to_surface, "input_face_to_surface");
  check(a.surface_face_to_input == b.surface_face_to_input, "surface_face_to_input");
  check(a.corner_vertex == b.corner_vertex, "corner_vertex");
  check(a.twin == b.twin, "twin");
  check(a.halfedges.size() == b.halfedges.size() &&
            std::memcmp(a.halfedges.data(), b.halfedges.data(), a.halfedges.size() * sizeof(a.halfedges[0])) == 0,
        "halfedges");
  check(same_bits(a.corner_angle, b.corner_angle), "corner_angle");
  check(a.vertex_corner_offsets == b.vertex_corner_offsets, "vertex_corner_offsets");
  check(a.vertex_corners == b.vertex_corners, "vertex_corners");
  check(a.is_pseudo_source == b.is_pseudo_source, "is_pseudo_source");
  check(same_bits(a.fan_angle_start, b.fan_angle_start), "fan_angle_start");
  check(a.corner_enters_forward == b.corner_enters_forward, "corner_enters_forward");
  check(same_bits(a.fan_total_angle, b.fan_total_angle), "fan_total_angle");
  check(a.fan_closed == b.fan_closed, "fan_closed");
  check(a.fan_angles_reliable == b.fan_angles_reliable, "fan_angles_reliable");
  check(a.vertices_on_sides == b.vertices_on_sides, "vertices_on_sides");
  const double a_scales[] = {a.length_scale, a.mean_edge_length}, b_scales[] = {b.length_scale, b.mean_edge_length};
  check(same_bits(a_scales, b_scales), "length scales");
  if (differs.empty()) return testing::AssertionSuccess();
  return testing::AssertionFailure() << "differs in " << differs;
}

void expect_same_on_any_team(const MeshSoup& soup, const std::string& what) {
  for (bool weld : {false, true}) {
    const auto reference = build(soup, weld, 1, 0);
    for (unsigned threads : {2u, 3u, 8u})
      for (std::size_t grain : {std::size_t{0}, std::size_t{1}, std::size_t{7}}) {
        const auto parallel = build(soup, weld, threads, grain);
        EXPECT_TRUE(same_surface(*reference, *parallel))
            << what << (weld ? ", welded" : "") << ", " << threads << " threads, grain " << grain;
      }
  }
}

// A grid with the junk real files carry: a double-sided copy of some faces (either winding), faces that
// repeat a vertex, a book of pages on one edge, a bowtie, a seam of duplicate positions, a zero-length edge,
// vertices used by no face.
MeshSoup junk_soup(Random& random) {
  MeshSoup soup = exactgeo_test::random_grid_with_holes(random, 8 + static_cast<int>(random.below(6)), 7, 2);
  const std::size_t faces = soup.triangles.size() / 3;
  for (int copy = 0; copy < 6; ++copy) {
    const std::size_t f = random.below(faces);
    const std::uint32_t a = soup.triangles[3 * f], b = soup.triangles[3 * f + 1], c = soup.triangles[3 * f + 2];
    if (copy % 2) add_triangle(soup, a, c, b); else add_triangle(soup, b, c, a);
  }
  add_triangle(soup, 0, 0, 1);
  const std::uint32_t a = soup.triangles[0], b = soup.triangles[1];
  for (int page = 0; page < 3 + static_cast<int>(random.below(4)); ++page)
    add_triangle(soup, a, b, add_vertex(soup, {random.uniform(-1, 1), random.uniform(-1, 1), 1.0 + page}));
  const std::uint32_t hub = add_vertex(soup, {50, 50, 0});
  add_triangle(soup, hub, add_vertex(soup, {51, 50, 0}), add_vertex(soup, {51, 51, 0}));
  add_triangle(soup, hub, add_vertex(soup, {49, 50, 0}), add_vertex(soup, {49, 49, 0}));
  const std::uint32_t seam = add_vertex(soup, exactgeo_test::vertex_position(soup, soup.triangles[5]));
  add_triangle(soup, seam, soup.triangles[6], add_vertex(soup, {-3, -3, -0.0}));
  const std::uint32_t twin = add_vertex(soup, exactgeo_test::vertex_position(soup, soup.triangles[9]));
  add_triangle(soup, soup.triangles[9], twin, add_vertex(soup, {-5, 2, 1}));
  add_vertex(soup, {1e3, 1e3, 1e3});
  return exactgeo_test::randomly_rotated(soup, random);
}

TEST(MeshBuild, JunkBuildsTheSameOnAnyTeam) {
  Random random(3801);
  for (int i = 0; i < 12; ++i) {
    const MeshSoup soup = junk_soup(random);
    // The junk is there to be handled.
    const auto surface = build(soup, false, 1, 0);
    const exactgeo::MeshReport& report = surface->report;
    EXPECT_GT(report.duplicate_faces, 0u);
    EXPECT_GT(report.faces_repeating_a_vertex, 0u);
    EXPECT_GT(report.non_manifold_edges, 0u);
    EXPECT_GT(report.non_manifold_vertices, 0u);
    EXPECT_GT(report.duplicate_positions, 0u);
    EXPECT_GT(report.zero_length_edges, 0u);
    EXPECT_GT(report.unreferenced_vertices, 0u);
    expect_same_on_any_team(soup, "junk soup " + std::to_string(i));
  }
}

TEST(MeshBuild, HeightFieldsBuildTheSameOnAnyTeam) {
  Random random(3802);
  for (int i = 0; i < 6; ++i)
    expect_same_on_any_team(exactgeo_test::random_height_field(random, 10 + i, 9, 0.5, i % 2 == 0),
                            "height field " + std::to_string(i));
  // Several of the geometry's blocks of faces, whose lengths are summed block by block.
  expect_same_on_any_team(exactgeo_test::random_height_field(random, 61, 37, 0.5, true), "larger height field");
  // T-junctions closed by slivers: their vertices are listed on the sides of the faces beyond.
  const MeshSoup junctions =
      exactgeo_test::with_t_junctions(exactgeo_test::random_height_field(random, 40, 30, 0.5, true), random, 300);
  EXPECT_FALSE(build(junctions, false, 1, 0)->vertices_on_sides.empty());
  expect_same_on_any_team(junctions, "height field with T-junctions");
}

// The mean edge length is summed in blocks of faces on the team: it is still the mean of the halfedges'
// lengths (to rounding), on any team.
TEST(MeshBuild, MeanEdgeLengthIsTheMeanOfTheHalfedges) {
  Random random(3804);
  const MeshSoup soup = exactgeo_test::random_height_field(random, 61, 37, 0.5, true);
  for (unsigned threads : {1u, 3u}) {
    const auto surface = build(soup, false, threads, 0);
    long double total = 0;
    for (const exactgeo::detail::HalfedgeGeometry& g : surface->halfedges) total += g.length;
    const double mean = static_cast<double>(total / static_cast<long double>(surface->halfedges.size()));
    EXPECT_GT(surface->face_count(), 4000u);
    EXPECT_NEAR(surface->mean_edge_length, mean, 1e-14 * mean) << threads << " threads";
  }
}

// Mesh(positions, triangles) copies the caller's arrays on the build's team (a mesh large enough for three
// threads, on as many as the machine has): the same surface as a build that takes the arrays over, and the caller's
// arrays are its own again afterwards: writing over them changes nothing in the mesh.
TEST(MeshBuild, BuildFromTheCallersArraysKeepsItsOwnCopies) {
  Random random(6007);
  MeshSoup soup = exactgeo_test::random_height_field(random, 180, 180, 0.5, true);
  ASSERT_GE(soup.triangles.size() / 3, 3 * exactgeo::detail::kFacesPerBuildThread);
  const MeshSoup original = soup;
  for (unsigned threads : {1u, 3u}) {
    const auto copied =
        exactgeo::detail::build_surface_from_copies(soup.positions, soup.triangles, {.threads = threads});
    EXPECT_EQ(copied->build_stats.threads, std::min(threads, exactgeo::detail::threads_or_cores(0)));
    std::fill(soup.positions.begin(), soup.positions.end(), 7.0);
    std::fill(soup.triangles.begin(), soup.triangles.end(), 0u);
    EXPECT_TRUE(same_surface(*build(original, false, threads, 0), *copied)) << threads << " threads";
    EXPECT_TRUE(same_bits(copied->input_positions, original.positions)) << threads << " threads";
    EXPECT_EQ(copied->input_triangles, original.triangles) << threads << " threads";
    soup = original;
  }
}

TEST(MeshBuild, SharedMeshesBuildTheSameOnAnyTeam) {
  EXACTGEO_SKIP_IF_NO_SHARED_MESHES();
  for (const char* name : {"beetle.obj", "suzanne.obj", "teapot.obj", "cow.obj"}) {
    const std::optional<MeshSoup> soup = exactgeo_test::load_shared_mesh(name);
    expect_same_on_any_team(*soup, name);
  }
}

}  // namespace

namespace {

TEST(MeshBuild, ReportsProgressAndStopsOnRequest) {
  Random random(3803);
  const MeshSoup soup = exactgeo_test::random_height_field(random, 30, 30, 0.5, true);
  std::vector<double> fractions;
  const exactgeo::Mesh mesh(soup, {.progress = [&](double f) { fractions.push_back(f); }});
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);

  std::stop_source stop;
  stop.request_stop();
  try {
    const exactgeo::Mesh stopped(soup, {.stop = stop.get_token()});
    FAIL() << "a stopped build returned a mesh";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::cancelled);
  }
}

}  // namespace
