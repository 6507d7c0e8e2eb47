// Stopping on request (GeodesicOptions::stop): a stopped run throws Error(cancelled) within milliseconds,
// whichever thread asks, and leaves the solver as good as new.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <stop_token>
#include <thread>
#include <vector>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/many_sources.hpp"

namespace {

using exactgeo::Mesh;

const Mesh& large_torus() {
  static const Mesh mesh(exactgeo::make_bumpy_torus(160, 80));  // 12,800 vertices: several checkpoints
  return mesh;
}

void expect_cancelled(const auto& run) {
  try {
    run();
    ADD_FAILURE() << "the run was not stopped";
  } catch (const exactgeo::Error& e) {
    EXPECT_EQ(e.code(), exactgeo::ErrorCode::cancelled) << e.what();
  }
}

TEST(Stop, AStoppedTokenEndsEveryVariantAndTheSolverStaysUsable) {
  const Mesh& mesh = large_torus();
  std::stop_source stop;
  stop.request_stop();
  for (const auto& entry : exactgeo::kAlgorithmNames) {
    const exactgeo::Algorithm algorithm = entry.first;  // a plain variable: lambdas capture it on every compiler
    exactgeo::GeodesicSolver solver(mesh);
    expect_cancelled([&] { solver.solve(std::vector<std::uint32_t>{0}, {}, {.algorithm = algorithm, .stop = stop.get_token()}); });
    const exactgeo::GeodesicResult& again = solver.solve(std::vector<std::uint32_t>{0}, {}, {.algorithm = algorithm});
    EXPECT_EQ(again.distances, exactgeo::geodesic_distance(mesh, 0, {.algorithm = algorithm}).distances) << entry.second;
  }
}

TEST(Stop, ManySourcesStopBetweenRunsEvenOnSmallMeshes) {
  // 42 vertices: no run reaches a checkpoint, so the loops over sources must check themselves.
  const Mesh mesh(exactgeo::make_icosphere(1));
  std::stop_source stop;
  stop.request_stop();
  const std::vector<std::uint32_t> sources = {0, 1, 2, 3};
  const exactgeo::MatrixOptions options{.geodesic = {.stop = stop.get_token()}, .threads = 2};
  expect_cancelled([&] { exactgeo::distance_matrix(mesh, sources, options); });
  expect_cancelled([&] { exactgeo::farthest_point_sampling(mesh, 10, 0, {.stop = stop.get_token()}); });
}

TEST(Stop, AnotherThreadStopsALongMatrix) {
  const Mesh& mesh = large_torus();
  std::vector<std::uint32_t> sources(100000, 0);  // minutes of work: only a stop ends it early
  std::stop_source stop;
  std::jthread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    stop.request_stop();
  });
  expect_cancelled([&] {
    exactgeo::for_each_distance_block(mesh, sources, {.geodesic = {.stop = stop.get_token()}, .threads = 2},
                                      [](std::size_t, std::span<const double>) {});
  });
}

}  // namespace
