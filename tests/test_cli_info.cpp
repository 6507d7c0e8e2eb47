// The `info` command: every MeshReport field, as JSON and as text.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/shapes.hpp"

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

// info reports every field of the library's MeshReport, with the library's values.
TEST_F(Cli, InfoJsonHasEveryReportField) {
  const RunResult result = run("info @torus --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json info = nlohmann::json::parse(result.out);
  const exactgeo::MeshReport report = exactgeo::Mesh(exactgeo::make_bumpy_torus(64, 36)).report();
  exactgeo::for_each_report_field([&](const char* name, auto member, const char*) {
    ASSERT_TRUE(info.contains(name)) << name;
    EXPECT_EQ(info[name].get<std::size_t>(), report.*member) << name;
  });
  EXPECT_EQ(info["mesh"], "@torus");
  // The demo torus: 64 x 36 segments, closed, one piece, saddles between the bumps.
  EXPECT_EQ(info["vertices"], 64 * 36);
  EXPECT_EQ(info["faces"], 2 * 64 * 36);
  EXPECT_EQ(info["boundary_edges"], 0);
  EXPECT_EQ(info["components"], 1);
  EXPECT_GT(info["saddle_vertices"].get<int>(), 0);
}

TEST_F(Cli, InfoTextListsEveryReportField) {
  const RunResult result = run("info @grid:3:2");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  exactgeo::for_each_report_field([&](const char* name, auto, const char*) {
    EXPECT_NE(result.out.find(std::string("\n") + name + " "), std::string::npos) << name;
  });
}

}  // namespace
