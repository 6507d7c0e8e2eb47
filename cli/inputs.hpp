// What the commands read from their arguments: the mesh (a file or a built-in shape), sources, targets and
// vertex lists. Syntax is checked while parsing (a usage error, exit 1); values against the mesh once it is
// loaded (exactgeo::Error, exit 2).
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/exactgeo.hpp"

namespace exactgeo::cli {

// An option taking several values (--source 0 911, or repeated). Such an option would also take a MESH
// written after it as its last value: it is moved back to MESH after parsing, so that
// `distance --source 0 911 bunny.obj` works as well as `distance bunny.obj --source 0 911`.
struct ListOption {
  CLI::Option* option;
  std::vector<std::string>* values;
};

// MESH and --weld, which every command takes; the command's list options and the checks that run once
// MESH is known (one callback per command, installed by add_mesh_options).
struct MeshArguments {
  std::string name;  // a file or a built-in mesh such as @torus
  bool weld = false;
  std::vector<ListOption> lists;
  std::vector<std::function<void()>> checks;  // after parsing; throw CLI::ParseError (a usage error)
  std::function<bool()> mesh_unused;          // set and true: MESH may be left out (matrix --status)
};
void add_mesh_options(CLI::App& command, MeshArguments& mesh);

// A list option bound to `values`: several values per use, and repeatable.
CLI::Option* add_list_option(CLI::App& command, MeshArguments& mesh, const std::string& name,
                             std::vector<std::string>& values, const std::string& help);

struct LoadedMesh {
  exactgeo::Mesh mesh;
  double read_seconds;   // reading the file or generating the shape
  double build_seconds;  // validating and building the Mesh, after the read
};
// Read and built on `threads` threads (0: one per core), the command's --threads.
LoadedMesh load_mesh(const MeshArguments& arguments, const std::optional<unsigned>& threads = {});

// --source, --source-point and --source-xyz, at least one of them.
struct SourceArguments {
  std::vector<std::string> vertices;  // syntax checked while parsing, converted after loading
  std::vector<std::string> points;
  std::vector<std::string> xyz;  // points in space, files or lists: read once the mesh is loaded
};
void add_source_options(CLI::App& command, MeshArguments& mesh, SourceArguments& sources);

// The sources as the library takes them: vertex indices alone keep the vertex-source semantics (every copy
// of a split vertex is a source); with points, vertices become points too. Vertices are numbered first, then
// --source-point, then --source-xyz (the closest surface point of each).
struct Sources {
  std::vector<std::uint32_t> vertices;
  std::vector<exactgeo::SurfacePoint> points;
  bool as_points = false;
};
Sources read_sources(const SourceArguments& arguments, const exactgeo::Mesh& mesh);
// The sources as the user wrote them, for summaries.
std::string describe_sources(const SourceArguments& arguments);

const exactgeo::GeodesicResult& solve(exactgeo::GeodesicSolver& solver, const Sources& sources,
                                      std::span<const exactgeo::SurfacePoint> targets,
                                      const exactgeo::GeodesicOptions& options);

// "-" as a list option's value: standard input, read whole. One value of the command can be "-".
inline constexpr std::string_view kStandardInput = "-";

// Targets: entries separated by spaces, newlines or ';', each a point F:b0,b1,b2 or vertex indices separated
// by commas. `text` is the argument itself or a file's contents; `origin` names it in messages, and `element`
// each entry ("target", or "point" for --query-points).
std::vector<exactgeo::SurfacePoint> parse_targets(const std::string& text, const exactgeo::Mesh& mesh,
                                                  const std::string& origin, std::string_view element = "target");
// The targets of a list option (distance --targets), each value a list as above, a file holding one (text, a
// CSV file with a vertex column, or a .npy array of vertex indices of any integer dtype) or "-" (standard
// input, in any form a file takes).
std::vector<exactgeo::SurfacePoint> read_targets(const std::vector<std::string>& arguments,
                                                 const exactgeo::Mesh& mesh, const std::string& option,
                                                 std::string_view element = "target");

// Pairs of points (pairs --pairs): each value a list of pairs, a file holding one or "-" (standard input).
// As text, pairs are separated by newlines or ';' and each is two points as targets are written (vertex
// indices or points F:b0,b1,b2, separated by spaces, or by a comma between vertex indices; a first line
// without a digit, such as a CSV header a,b, is skipped); or a .npy array of shape (n, 2) of vertex indices of
// any integer dtype.
struct Pairs {
  std::vector<exactgeo::SurfacePoint> a, b;
};
Pairs read_pairs(const std::vector<std::string>& arguments, const exactgeo::Mesh& mesh, const std::string& option);

// Points in space, as --points, --source-xyz and --target-xyz take them: X,Y,Z (or X Y Z), points separated
// by newlines or ';'. `text` is a file's contents (standard input's for -) or the argument itself: a point cloud's .xyz lines or a CSV
// file of x,y,z, whose header (a first line without numbers) is skipped. Returns x0 y0 z0 x1 ...; `origin`
// names the option in messages.
std::vector<double> parse_xyz_list(const std::string& text, const std::string& origin);
// The closest surface points (exactgeo::locate) of the points in space that a list option's values give,
// with their distances to the surface.
exactgeo::LocateResult locate_listed(const std::vector<std::string>& arguments, const exactgeo::Mesh& mesh,
                                     const std::string& origin, unsigned threads = 0);

// Vertex indices separated by spaces, newlines, ',' or ';'.
std::vector<std::uint32_t> parse_vertex_list(const std::string& text, const std::string& origin);
// What a listed vertex must be: in range and used by a face (a source, a target point), or only in range (a
// column of a distance matrix, +inf where no face uses the vertex, as in the full matrix).
enum class VertexCheck { used_by_a_face, in_range };
// The vertices of a list option (matrix --sources and --targets), each value a list as above, a file (text as
// above, a CSV file with a vertex column, or a .npy array of any integer dtype) or "-" (standard input, in any
// form a file takes), concatenated. Each is checked against the mesh as `check` says; a message names the
// value, and the element of a .npy array, at fault.
std::vector<std::uint32_t> read_vertex_list(const std::vector<std::string>& arguments, const exactgeo::Mesh& mesh,
                                            const std::string& option, VertexCheck check);

// --threads for commands that run one propagation: how many threads share it. Unset, the library's
// recommendation for the mesh (every core on large meshes); 0, one per core.
void add_threads_option(CLI::App& command, std::optional<unsigned>& threads);
unsigned threads_for(const std::optional<unsigned>& threads, const exactgeo::Mesh& mesh);

// A check for options taking a distance: a number, not negative.
const CLI::Validator& distance_check();
// A check for options taking a count: digits only, so that "-1" is an error rather than a huge number, and at
// most `maximum`, the largest value the option's variable holds (CLI11 would store a larger one clamped).
CLI::Validator count_check(std::uint64_t maximum = std::numeric_limits<std::uint64_t>::max());

}  // namespace exactgeo::cli
