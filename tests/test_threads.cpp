// One run on several threads (GeodesicOptions::threads): on generated meshes of many shapes, every feature
// gives, with 2, 3, 8 and 16 threads, the answer of the sequential engine (one thread) to 1e-14 of the largest
// distance, with the same vertices reachable and the same nearest sources. (Which thread crosses what, and
// when, may change the last bits between runs.) The oracle tests check the threaded runs against CGAL on
// the shared meshes.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <functional>
#include <string>
#include <stop_token>
#include <thread>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "test_meshes.hpp"
#include "worker_pool.hpp"

namespace {

using exactgeo::GeodesicOptions;
using exactgeo::GeodesicResult;
using exactgeo::Mesh;

constexpr unsigned kThreadCounts[] = {2, 3, 8, 16};
constexpr double kAgreement = 1e-14;

// A fine grid with a needle on one boundary edge: a triangle thousands of cells long, like a scan's junk. The
// mean edge is about 2.4, so the needle's tip lies over 3,000 bands (of half a mean edge) beyond the grid:
// farther than the parallel bands' queue files vertices ahead, so the tip moves on through its last slot.
exactgeo::MeshSoup grid_with_needle() {
  constexpr int kCells = 32;
  exactgeo::MeshSoup soup = exactgeo::make_grid(kCells, kCells, kCells, kCells);  // vertex (i, j) is j * 33 + i
  const std::uint32_t tip = exactgeo_test::add_vertex(soup, {kCells / 2 + 0.5, -4000.0, 0.0});
  exactgeo_test::add_triangle(soup, kCells / 2 + 1, kCells / 2, tip);  // on the edge (16, 0)-(17, 0)
  return soup;
}

// The generated meshes: smooth and noisy height fields (saddles everywhere), a bumpy torus (closed, no
// boundary), grids with holes (boundary vertices as pseudo-sources), a fine icosphere and a grid with a
// needle.
std::vector<std::pair<std::string, Mesh>> generated_meshes() {
  std::vector<std::pair<std::string, Mesh>> meshes;
  exactgeo_test::Random random(2016);
  meshes.emplace_back("smooth height field", Mesh(exactgeo_test::random_height_field(random, 24, 24, 0.3, true)));
  meshes.emplace_back("noisy height field", Mesh(exactgeo_test::random_height_field(random, 20, 20, 0.05, false)));
  meshes.emplace_back("bumpy torus", Mesh(exactgeo::make_bumpy_torus(48, 24)));
  meshes.emplace_back("grid with holes", Mesh(exactgeo_test::random_grid_with_holes(random, 24, 20, 4)));
  meshes.emplace_back("icosphere", Mesh(exactgeo::make_icosphere(4)));
  meshes.emplace_back("grid with a needle", Mesh(grid_with_needle()));
  return meshes;
}

GeodesicOptions with_threads(GeodesicOptions options, unsigned threads) {
  options.threads = threads;
  return options;
}

// Each threaded result agrees with the sequential one to kAgreement, reachability included, and names the
// same nearest source for every vertex but those that two sources reach at distances within kAgreement of
// each other: there the tie goes to whichever path arrives first. `per_source` holds each labelled source's
// own distances (needed only with several sources).
void expect_same_for_every_thread_count(const std::string& what,
                                        const std::function<GeodesicResult(const GeodesicOptions&)>& run,
                                        const GeodesicOptions& options = {},
                                        const std::vector<std::vector<double>>& per_source = {}) {
  const GeodesicResult sequential = run(with_threads(options, 1));
  const double largest = exactgeo_test::max_finite(sequential.distances);
  for (unsigned threads : kThreadCounts) {
    const GeodesicResult result = run(with_threads(options, threads));
    const std::string where = what + ", " + std::to_string(threads) + " threads";
    EXPECT_TRUE(exactgeo_test::distances_match(result.distances, sequential.distances, kAgreement)) << where;
    EXPECT_TRUE(exactgeo_test::distances_match(result.target_distances, sequential.target_distances, kAgreement)) << where;
    ASSERT_EQ(result.nearest_source.size(), sequential.nearest_source.size()) << where;
    for (std::size_t v = 0; v < result.nearest_source.size(); ++v) {
      const std::uint32_t label = result.nearest_source[v], expected = sequential.nearest_source[v];
      if (label == expected) continue;
      ASSERT_TRUE(label < per_source.size() && expected < per_source.size())
          << where << ", vertex " << v << ": nearest source " << label << " instead of " << expected;
      EXPECT_LE(std::abs(per_source[label][v] - per_source[expected][v]), kAgreement * largest)
          << where << ", vertex " << v << ": nearest source " << label << " instead of " << expected << ", not a tie";
    }
  }
}

TEST(Threads, EveryVariantGivesTheSequentialDistancesOnEveryThreadCount) {
  for (const auto& entry : generated_meshes()) {
    const std::string& name = entry.first;  // not a structured binding: lambdas capture these on every compiler
    const Mesh& mesh = entry.second;
    for (const GeodesicOptions& variant : exactgeo_test::kAllVariants)
      expect_same_for_every_thread_count(name + ", " + exactgeo_test::variant_label(variant),
                                         [&](const GeodesicOptions& o) { return exactgeo::geodesic_distance(mesh, 0, o); },
                                         variant);
  }
}

TEST(Threads, SeveralSourcesLabelsAndPointSources) {
  for (const auto& entry : generated_meshes()) {
    const std::string& name = entry.first;  // not a structured binding: lambdas capture these on every compiler
    const Mesh& mesh = entry.second;
    const auto n = static_cast<std::uint32_t>(mesh.vertex_count());
    const std::vector<std::uint32_t> vertices = {0, n / 2, n - 1};
    std::vector<std::vector<double>> from_each_vertex;
    for (const std::uint32_t v : vertices) from_each_vertex.push_back(exactgeo::geodesic_distance(mesh, v).distances);
    expect_same_for_every_thread_count(name + ", three source vertices", [&](const GeodesicOptions& o) {
      return exactgeo::geodesic_distance(mesh, vertices, o);
    }, {}, from_each_vertex);
    const std::vector<exactgeo::SurfacePoint> points = {{.face = 0, .barycentric = {0.2, 0.3, 0.5}},
                                                        {.face = static_cast<std::uint32_t>(mesh.face_count() / 3), .barycentric = {0.5, 0.5, 0}}};
    std::vector<std::vector<double>> from_each_point;
    for (const exactgeo::SurfacePoint& p : points)
      from_each_point.push_back(exactgeo::geodesic_distance(mesh, std::span(&p, 1)).distances);
    expect_same_for_every_thread_count(name + ", a face point and an edge point", [&](const GeodesicOptions& o) {
      return exactgeo::geodesic_distance(mesh, points, o);
    }, {}, from_each_point);
  }
}

TEST(Threads, CutOffsAndTargets) {
  for (const auto& entry : generated_meshes()) {
    const std::string& name = entry.first;  // not a structured binding: lambdas capture these on every compiler
    const Mesh& mesh = entry.second;
    const double radius = exactgeo_test::max_finite(exactgeo::geodesic_distance(mesh, 0).distances) / 3;
    expect_same_for_every_thread_count(name + ", cut-off", [&](const GeodesicOptions& o) {
      return exactgeo::geodesic_distance(mesh, 0, o);
    }, {.max_distance = radius});
    const std::vector<exactgeo::SurfacePoint> targets = {{.face = static_cast<std::uint32_t>(mesh.face_count() / 2), .barycentric = {0.1, 0.1, 0.8}},
                                                         {.face = static_cast<std::uint32_t>(mesh.face_count() / 4), .barycentric = {0, 1, 0}}};
    expect_same_for_every_thread_count(name + ", targets", [&](const GeodesicOptions& o) {
      exactgeo::GeodesicSolver solver(mesh);
      const std::uint32_t source = 0;
      return solver.solve(std::span(&source, 1), targets, o);
    });
  }
}

TEST(Threads, PathsHaveTheLengthOfTheirDistance) {
  for (const auto& entry : generated_meshes()) {
    const std::string& name = entry.first;  // not a structured binding: lambdas capture these on every compiler
    const Mesh& mesh = entry.second;
    exactgeo::GeodesicSolver solver(mesh);
    const std::uint32_t source = 0;
    const GeodesicResult& result = solver.solve(std::span(&source, 1), {}, {.threads = 3});
    const double largest = exactgeo_test::max_finite(result.distances);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); v += 7) {
      const exactgeo::GeodesicPath path = solver.path_to_vertex(v);
      if (std::isinf(result.distances[v])) continue;
      EXPECT_NEAR(path.length, result.distances[v], 1e-9 * largest) << name << ", vertex " << v;
    }
  }
}

TEST(Threads, ProgressIsReportedAndAStopEndsTheRun) {
  const Mesh mesh(exactgeo::make_bumpy_torus(192, 96));  // enough vertices for several checkpoints
  exactgeo::GeodesicSolver solver(mesh);
  std::vector<double> fractions;
  solver.set_progress([&](double f) { fractions.push_back(f); });
  const std::uint32_t source = 0;
  solver.solve(std::span(&source, 1), {}, {.threads = 2});
  ASSERT_FALSE(fractions.empty());
  for (std::size_t i = 1; i < fractions.size(); ++i) EXPECT_LE(fractions[i - 1], fractions[i]);

  std::stop_source stop;
  stop.request_stop();
  try {
    solver.solve(std::span(&source, 1), {}, {.threads = 2, .stop = stop.get_token()});
    ADD_FAILURE() << "the run was not stopped";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::cancelled) << e.what();
  }
  // The solver, and its threads, stay usable.
  EXPECT_TRUE(exactgeo_test::distances_match(solver.solve(std::span(&source, 1), {}, {.threads = 2}).distances,
                                             exactgeo::geodesic_distance(mesh, 0).distances, kAgreement));
}

// The instruments of a threaded run (GeodesicStats' parallel_* fields and band_timeline) add up: the bands'
// records to the run's counts and times, each thread's time in a band to no more than the band's.
TEST(Threads, TheInstrumentsOfTheBandsAddUp) {
  const Mesh mesh(exactgeo::make_bumpy_torus(96, 48));
  const exactgeo::GeodesicStats one = exactgeo::geodesic_distance(mesh, 0, {.collect_timings = true}).stats;
  EXPECT_GT(one.list_crossings, 0u);
  EXPECT_TRUE(one.band_timeline.empty());
  EXPECT_EQ(one.parallel_busy_seconds, 0.0);
  EXPECT_GT(one.setup_seconds, 0.0);
  EXPECT_LT(one.setup_seconds, one.propagation_seconds);
  for (unsigned threads : kThreadCounts) {
    const std::string where = std::to_string(threads) + " threads";
    const exactgeo::GeodesicStats timed =
        exactgeo::geodesic_distance(mesh, 0, {.collect_timings = true, .threads = threads}).stats;
    ASSERT_EQ(timed.band_timeline.size(), timed.parallel_bands) << where;
    std::uint64_t vertices = 0, crossings = 0, depth = 0;
    double seconds = 0, busy = 0;
    for (const exactgeo::GeodesicStats::Band& band : timed.band_timeline) {
      vertices += band.vertices;
      crossings += band.crossings;
      depth += band.depth;
      seconds += band.seconds;
      busy += band.busy_seconds;
      EXPECT_LE(band.busy_seconds, threads * band.seconds * (1 + 1e-9)) << where;
    }
    EXPECT_EQ(vertices, timed.vertex_pops) << where;
    EXPECT_EQ(crossings, timed.list_crossings) << where;
    EXPECT_EQ(depth, timed.parallel_critical_path) << where;
    EXPECT_NEAR(seconds, timed.parallel_seconds, 1e-9) << where;
    EXPECT_NEAR(busy, timed.parallel_busy_seconds, 1e-9) << where;
    EXPECT_GT(timed.parallel_busy_seconds, 0.0) << where;
    EXPECT_LE(timed.parallel_busiest_thread_seconds, timed.parallel_seconds * (1 + 1e-9)) << where;
    EXPECT_LE(timed.parallel_busy_seconds, threads * timed.parallel_busiest_thread_seconds * (1 + 1e-9)) << where;
    EXPECT_LE(timed.parallel_busy_seconds + timed.parallel_start_seconds + timed.parallel_starved_seconds,
              threads * timed.parallel_seconds * (1 + 1e-9)) << where;
    EXPECT_LE(timed.parallel_lock_wait_seconds, timed.parallel_busy_seconds) << where;
    // The set-up comes before the first band: both lie inside the whole, apart.
    EXPECT_GT(timed.setup_seconds, 0.0) << where;
    EXPECT_LE(timed.setup_seconds + timed.parallel_seconds, timed.propagation_seconds) << where;
    // Re-crossed lists: more crossings than one thread's, never fewer than the lists one thread crosses once.
    EXPECT_GE(timed.list_crossings, one.list_crossings / 2) << where;
    // Untimed, the counts stay and the timeline is not kept.
    const exactgeo::GeodesicStats untimed = exactgeo::geodesic_distance(mesh, 0, {.threads = threads}).stats;
    EXPECT_TRUE(untimed.band_timeline.empty()) << where;
    EXPECT_GT(untimed.list_crossings, 0u) << where;
    EXPECT_EQ(untimed.parallel_busy_seconds, 0.0) << where;
    EXPECT_GT(untimed.setup_seconds, 0.0) << where;  // measured with or without the timers
  }
}

TEST(Threads, DistanceMatricesSpreadSourcesAndRunEachOnOneThread) {
  const Mesh mesh(exactgeo::make_bumpy_torus(32, 16));
  const std::vector<std::uint32_t> sources = {0, 5, 9};
  EXPECT_EQ(exactgeo::distance_matrix(mesh, sources, {.geodesic = {.threads = 8}, .threads = 2}),
            exactgeo::distance_matrix(mesh, sources, {.geodesic = {}, .threads = 1}));
}

TEST(Threads, ZeroMeansOnePerCoreAndAbsurdCountsAreRefused) {
  const Mesh mesh(exactgeo::make_bumpy_torus(32, 16));
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const GeodesicResult all_cores = exactgeo::geodesic_distance(mesh, 0, {.threads = 0});
  EXPECT_TRUE(exactgeo_test::distances_match(all_cores.distances, exactgeo::geodesic_distance(mesh, 0).distances, kAgreement));
  EXPECT_EQ(all_cores.stats.parallel_bands > 0, cores > 1);
  try {
    exactgeo::geodesic_distance(mesh, 0, {.threads = 100000});
    ADD_FAILURE() << "100000 threads were accepted";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("threads"), std::string::npos) << e.what();
  }
}

TEST(Threads, TheRecommendationGivesEachThreadTenThousandFacesUpToEveryCore) {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  EXPECT_EQ(exactgeo::recommended_threads(Mesh(exactgeo::make_icosphere(1))), 1u);              // 80 faces
  EXPECT_EQ(exactgeo::recommended_threads(Mesh(exactgeo::make_icosphere(5))), std::min(cores, 2u));   // 20,480
  EXPECT_EQ(exactgeo::recommended_threads(Mesh(exactgeo::make_icosphere(6))), std::min(cores, 8u));   // 81,920
  EXPECT_EQ(exactgeo::recommended_threads(Mesh(exactgeo::make_icosphere(7))), std::min(cores, 32u));  // 327,680
}

// The thread team, with more threads than a small machine has cores, so that threads are preempted within
// batches: in each of many batches of varying size every item runs exactly once, and a batch returns only
// when all its items are done.
TEST(WorkerPool, EveryItemOfEveryBatchRunsOnceBeforeTheBatchReturns) {
  exactgeo::detail::WorkerPool pool(8);
  std::vector<std::atomic<int>> runs(300);
  exactgeo_test::Random random(7);
  for (int batch = 0; batch < 3000; ++batch) {
    const std::size_t count = 2 + random.below(290);
    for (std::size_t i = 0; i < count; ++i) runs[i] = 0;
    pool.run(count, [&](std::size_t item, unsigned thread) {
      ASSERT_LT(thread, 8u);
      runs[item].fetch_add(1);
    });
    for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1) << "batch " << batch << ", item " << i;
  }
}

TEST(WorkerPool, AFailingItemIsRethrownAndThePoolStaysUsable) {
  exactgeo::detail::WorkerPool pool(3);
  EXPECT_THROW(pool.run(100, [](std::size_t item, unsigned) {
                 if (item == 37) throw std::runtime_error("item 37");
               }),
               std::runtime_error);
  std::atomic<int> total{0};
  pool.run(100, [&](std::size_t, unsigned) { total.fetch_add(1); });
  EXPECT_EQ(total.load(), 100);
}

}  // namespace
