// The `path` command: straight lines on flat meshes, coincident vertices, targets at split vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

TEST_F(Cli, PathOnAFlatGridIsTheDiagonal) {
  for (const char* name : {"p.csv", "p.obj", "p.json"})
    ASSERT_EQ(run("path @grid:4:4 --source 0 --target 24 --out " + arg(name)).exit_code, 0) << name;
  const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
  EXPECT_NEAR(path_json["length"].get<double>(), 4 * std::sqrt(2.0), 1e-12);
  const auto& points = path_json["points"];
  ASSERT_GE(points.size(), 2u);
  for (const auto& p : points) EXPECT_NEAR(p[0].get<double>(), p[1].get<double>(), 1e-12);  // on the diagonal
  EXPECT_EQ(path_json["locations"].front()["vertex"], 0);
  EXPECT_EQ(path_json["locations"].back()["vertex"], 24);
  const std::string obj = read_file(path("p.obj"));
  EXPECT_EQ(static_cast<std::size_t>(std::count(obj.begin(), obj.end(), 'v')), points.size());
  EXPECT_NE(obj.find("\nl 1 2"), std::string::npos) << obj;
  const std::string csv = read_file(path("p.csv"));
  EXPECT_EQ(csv.rfind("x,y,z,kind,a,b,t\n", 0), 0u);
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), points.size() + 1);
  const RunResult printed = run("path @grid:4:4 --source-point 0:0.2,0.3,0.5 --target 24");
  EXPECT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_NE(printed.out.find("path length"), std::string::npos) << printed.out;
}

// Issue 34, finding 1: vertices 2 and 3 coincide, an edge of the zero-area face (1 3 2) of zero length, and
// `path` exited 3 with "internal error: path tracing failed". The surface is the flat triangle 0 1 2, so the
// path is the straight segment, to either vertex.
TEST_F(Cli, PathThroughCoincidentVertices) {
  write_file(path("d.obj"), "v 0 0 0\nv 1 0 1\nv 0 1 2\nv 0 1 2\nf 1 2 3\nf 2 4 3\n");
  for (const int target : {2, 3}) {
    const RunResult result =
        run("path " + arg("d.obj") + " --source 0 --target " + std::to_string(target) + " --out " + arg("p.json"));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
    EXPECT_NEAR(path_json["length"].get<double>(), std::sqrt(5.0), 1e-12 * std::sqrt(5.0)) << "target " << target;
    EXPECT_EQ(path_json["locations"].front()["vertex"], 0);
    EXPECT_EQ(path_json["locations"].back()["vertex"], target);
  }
}

// Issue 34, finding 2: a vertex named as a target where the mesh policy splits it (vertex 0 of a bowtie, two
// triangles meeting there only) stood on the first face using it, so `distance --targets` and `path --target`
// gave inf from the other wing, while `--out` gave the smallest over its copies. Each wing runs straight along
// an edge to vertex 0.
TEST_F(Cli, TargetAtASplitVertexIsThePerVertexDistance) {
  write_file(path("bowtie.obj"), "v 0 0 0\nv 3 0 0\nv 0 4 0\nv -2 0 0\nv 0 0 -1\nf 1 2 3\nf 1 4 5\n");
  for (const auto& [source, along_edge] : {std::pair{1, 3.0}, {2, 4.0}, {3, 2.0}, {4, 1.0}}) {
    SCOPED_TRACE(testing::Message() << "source " << source);
    const std::string mesh_and_source = arg("bowtie.obj") + " --source " + std::to_string(source);
    const RunResult result =
        run("distance " + mesh_and_source + " --targets 0 --target-out " + arg("t.txt") + " --out " + arg("d.txt"));
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_NEAR(parse_txt(path("t.txt")).at(0), along_edge, 1e-15 * along_edge);
    EXPECT_EQ(parse_txt(path("t.txt")).at(0), parse_txt(path("d.txt")).at(0));
    ASSERT_EQ(run("path " + mesh_and_source + " --target 0 --out " + arg("p.json")).exit_code, 0);
    const nlohmann::json path_json = nlohmann::json::parse(read_file(path("p.json")));
    EXPECT_NEAR(path_json["length"].get<double>(), along_edge, 1e-15 * along_edge);
    EXPECT_EQ(path_json["locations"].back()["vertex"], 0);
  }
}

}  // namespace
