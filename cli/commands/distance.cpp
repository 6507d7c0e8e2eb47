// exactgeo distance: geodesic distance from sources to every vertex (and to targets), written per vertex and
// per target, with statistics as JSON and a summary on stdout.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string_view>
#include <thread>
#include <utility>

#include "command.hpp"
#include "inputs.hpp"
#include "output_options.hpp"
#include "progress.hpp"
#include "report_fields.hpp"

namespace exactgeo::cli {
namespace {

struct DistanceArguments {
  MeshArguments mesh;
  SourceArguments sources;
  double max_distance = std::numeric_limits<double>::infinity();
  std::vector<std::string> targets;
  std::vector<std::string> target_xyz;
  std::string targets_beyond = "inf";
  std::vector<std::string> query_points;
  std::string query_out;
  bool labels = false;
  std::string out;
  std::string target_out;
  std::string stats;
  std::string algorithm = "vtp";
  bool no_rule1 = false;
  bool no_rule23 = false;
  bool timers = false;
  std::optional<unsigned> threads;
  bool quiet = false;
};

// The largest finite distance and how many are infinite.
struct Reach {
  double max_distance = 0.0;
  std::size_t unreachable = 0;
};

// --threads asked for more threads than the run shared (the summary and --stats give those it did): why.
void note_threads_not_used(const DistanceArguments& arguments, const exactgeo::GeodesicOptions& options,
                           const exactgeo::GeodesicStats& stats) {
  if (!arguments.threads) return;
  // Asked only here: the system reads a file for it.
  const unsigned asked = options.threads != 0 ? options.threads : std::thread::hardware_concurrency();
  if (stats.threads >= asked) return;
  const bool face_sorted =
      options.algorithm == exactgeo::Algorithm::ftp || options.algorithm == exactgeo::Algorithm::opftp;
  std::fprintf(stderr, "exactgeo: note: the run used %u of the %u threads asked for: %s\n", stats.threads, asked,
               face_sorted ? "the face-sorted variants (ftp, opftp) are sequential" : "the system would not start more");
}

Reach reach_of(std::span<const double> distances) {
  Reach reach;
  for (double distance : distances) {
    if (std::isinf(distance)) {
      ++reach.unreachable;
    } else {
      reach.max_distance = std::max(reach.max_distance, distance);
    }
  }
  return reach;
}

// Vertices used by faces yet unreachable, on a mesh with vertices at duplicate positions: most likely split
// at texture or normal seams by the program that wrote it; --weld joins them again.
void warn_if_seams_cut_the_surface(const DistanceArguments& arguments, const exactgeo::Mesh& mesh, const Reach& reach) {
  const exactgeo::MeshReport& report = mesh.report();
  if (arguments.mesh.weld || !arguments.targets.empty() || !arguments.target_xyz.empty() ||
      !std::isinf(arguments.max_distance) ||
      report.duplicate_positions == 0 || reach.unreachable <= report.unreferenced_vertices)
    return;
  std::fprintf(stderr,
               "exactgeo: warning: %zu of %zu vertices are unreachable, and %zu vertices repeat another's position "
               "(seams): --weld joins them\n",
               reach.unreachable - report.unreferenced_vertices, mesh.vertex_count(), report.duplicate_positions);
}

nlohmann::ordered_json stats_file(const DistanceArguments& arguments, const LoadedMesh& loaded,
                                  const Sources& sources, std::size_t targets, std::size_t queries,
                                  const exactgeo::GeodesicOptions& options, const exactgeo::GeodesicStats& stats,
                                  const Reach& reach, double write_seconds) {
  nlohmann::ordered_json json;
  json["mesh"] = arguments.mesh.name;
  json["vertices"] = loaded.mesh.vertex_count();
  json["faces"] = loaded.mesh.face_count();
  json["source"] = sources.vertices;
  json["source_points"] = arguments.sources.points;
  json["source_xyz"] = arguments.sources.xyz;
  json["targets"] = targets;
  json["max_distance_cutoff"] =
      std::isinf(arguments.max_distance) ? nlohmann::ordered_json() : nlohmann::ordered_json(arguments.max_distance);
  json["targets_beyond"] = arguments.targets_beyond;
  json["query_points"] = queries;
  json["algorithm"] = exactgeo::algorithm_name(options.algorithm);
  json["rule1"] = options.rule1;
  json["rule23"] = options.rule23;
  json["read_seconds"] = loaded.read_seconds;
  json["build_seconds"] = loaded.build_seconds;
  json["build_threads"] = loaded.mesh.build_stats().threads;
  json["build_timings"] = build_timings_json(loaded.mesh.build_stats());
  json.update(stats_json(stats, arguments.timers));
  json["write_seconds"] = write_seconds;
  json["max_distance"] = reach.max_distance;
  json["unreachable"] = reach.unreachable;
  json["mesh_report"] = report_json(loaded.mesh.report());
  json["version"] = exactgeo::kVersion;
  return json;
}

// The run's statistics, named as in the JSON without underscores: counts but those that stay zero in this
// variant, the time, and its phases when measured (indented under it).
void append_stats_rows(Rows& rows, const exactgeo::GeodesicStats& stats, bool timed) {
  exactgeo::for_each_stats_field([&](std::string_view name, auto member, exactgeo::StatsFieldKind kind, const char*) {
    const auto value = stats.*member;
    std::string label(name);
    if (kind == exactgeo::StatsFieldKind::count) {
      if (value == 0) return;
      std::replace(label.begin(), label.end(), '_', ' ');
      rows.emplace_back(std::move(label), std::to_string(value));
      return;
    }
    if (kind == exactgeo::StatsFieldKind::phase_seconds && !timed) return;
    label.resize(label.size() - std::string_view("_seconds").size());
    std::replace(label.begin(), label.end(), '_', ' ');
    if (kind == exactgeo::StatsFieldKind::phase_seconds) label = "  " + label;
    rows.emplace_back(std::move(label), format_number("%.4f s", double(value)));
  });
}

Rows summary(const DistanceArguments& arguments, const LoadedMesh& loaded, const exactgeo::GeodesicOptions& options,
             const exactgeo::GeodesicResult& result, std::size_t targets, std::span<const double> query_distances,
             const Reach& reach) {
  const std::size_t source_count =
      arguments.sources.vertices.size() + arguments.sources.points.size() + arguments.sources.xyz.size();
  const bool cut_off = targets > 0 || !std::isinf(arguments.max_distance);
  Rows rows = {{"mesh", arguments.mesh.name},
               {"vertices", std::to_string(loaded.mesh.vertex_count())},
               {"faces", std::to_string(loaded.mesh.face_count())},
               {source_count == 1 ? "source" : "sources", describe_sources(arguments.sources)}};
  if (options.algorithm != exactgeo::Algorithm::vtp || !options.rule1 || !options.rule23) {
    std::string variant(exactgeo::algorithm_name(options.algorithm));
    if (!options.rule1) variant += ", Rule 1 off";
    if (!options.rule23) variant += ", Rules 2 and 3 off";
    rows.emplace_back("algorithm", variant);
  }
  if (!std::isinf(arguments.max_distance)) rows.emplace_back("cut-off", format_number("%.12g", arguments.max_distance));
  rows.emplace_back("max distance", format_number("%.12g", reach.max_distance));
  rows.emplace_back(cut_off ? "unreachable or beyond" : "unreachable", std::to_string(reach.unreachable));
  rows.emplace_back("read", format_number("%.4f s", loaded.read_seconds));
  rows.emplace_back("build", format_number("%.4f s", loaded.build_seconds));
  if (arguments.timers)
    exactgeo::for_each_build_stats_field([&](std::string_view name, auto member, const char*) {
      if (!name.ends_with("_seconds")) return;
      std::string label(name.substr(0, name.size() - std::string_view("_seconds").size()));
      std::replace(label.begin(), label.end(), '_', ' ');
      rows.emplace_back("  " + label, format_number("%.4f s", double(loaded.mesh.build_stats().*member)));
    });
  append_stats_rows(rows, result.stats, arguments.timers);
  if (arguments.target_out.empty())
    for (std::size_t t = 0; t < targets; ++t) {
      std::string value = format_distance(result.target_distances[t]);
      if (arguments.labels) value += " (source " + std::to_string(label_value(result.target_nearest_source[t])) + ")";
      rows.emplace_back("target " + std::to_string(t), value);
    }
  if (arguments.query_out.empty())
    for (std::size_t q = 0; q < query_distances.size(); ++q)
      rows.emplace_back("point " + std::to_string(q), format_distance(query_distances[q]));
  return rows;
}

int run_distance(const DistanceArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.threads);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const Sources sources = read_sources(arguments.sources, mesh);
  std::vector<exactgeo::SurfacePoint> targets =
      arguments.targets.empty() ? std::vector<exactgeo::SurfacePoint>()
                                : read_targets(arguments.targets, mesh, "--targets");
  if (!arguments.target_xyz.empty()) {
    const exactgeo::LocateResult located = locate_listed(arguments.target_xyz, mesh, "--target-xyz");
    targets.insert(targets.end(), located.points.begin(), located.points.end());
  }
  const std::vector<exactgeo::SurfacePoint> query_points =
      arguments.query_points.empty() ? std::vector<exactgeo::SurfacePoint>()
                                     : read_targets(arguments.query_points, mesh, "--query-points", "point");
  // --targets-beyond exact: the run goes on until every target is final, whatever the cut-off; the cut-off
  // then applies to the vertex distances alone.
  const bool exact_targets = !targets.empty() && arguments.targets_beyond == "exact";

  const exactgeo::GeodesicOptions options{.algorithm = exactgeo::parse_algorithm(arguments.algorithm),
                                          .rule1 = !arguments.no_rule1,
                                          .rule23 = !arguments.no_rule23,
                                          .max_distance = exact_targets ? HUGE_VAL : arguments.max_distance,
                                          .collect_timings = arguments.timers,
                                          .threads = threads_for(arguments.threads, mesh),
                                          .keep_windows = !query_points.empty()};
  // The solver (its window lists and per-vertex state) goes before the outputs are written: they need only
  // the result, and the process's peak memory is the larger of the two phases, not their sum.
  std::vector<double> query_distances;
  exactgeo::GeodesicResult result = [&] {
    exactgeo::GeodesicSolver solver(mesh);
    Progress progress("vertices", mesh.vertex_count(), arguments.quiet);
    solver.set_progress([&](double fraction) {
      progress.update(static_cast<std::size_t>(fraction * static_cast<double>(mesh.vertex_count())));
    });
    solve(solver, sources, targets, options);
    progress.finish();
    if (!query_points.empty()) query_distances = solver.distance_at(query_points);
    return std::move(solver).result();
  }();
  if (exact_targets)
    for (std::size_t v = 0; v < result.distances.size(); ++v)
      if (result.distances[v] > arguments.max_distance) {
        result.distances[v] = HUGE_VAL;
        result.nearest_source[v] = exactgeo::kNoSource;
      }
  note_threads_not_used(arguments, options, result.stats);
  const Reach reach = reach_of(result.distances);
  warn_if_seams_cut_the_surface(arguments, mesh, reach);

  const auto labels_if_asked = [&](const std::vector<std::uint32_t>& labels) {
    return arguments.labels ? std::span<const std::uint32_t>(labels) : std::span<const std::uint32_t>();
  };
  const auto write_start = std::chrono::steady_clock::now();
  if (!arguments.out.empty())
    write_values(arguments.out, kVertexValueFormats,
                 {result.distances, labels_if_asked(result.nearest_source), "vertex", &mesh});
  if (!arguments.target_out.empty())
    write_values(arguments.target_out, kTargetValueFormats,
                 {result.target_distances, labels_if_asked(result.target_nearest_source), "target", nullptr});
  if (!arguments.query_out.empty())
    write_values(arguments.query_out, kTargetValueFormats, {query_distances, {}, "point", nullptr});
  const double write_seconds = seconds_since(write_start);
  if (!arguments.stats.empty())
    write_json(arguments.stats, stats_file(arguments, loaded, sources, targets.size(), query_points.size(), options,
                                           result.stats, reach, write_seconds));
  // The summary goes to stdout only when no output does.
  if (arguments.out.empty() && arguments.target_out != kStdout && arguments.query_out != kStdout)
    print_table(summary(arguments, loaded, options, result, targets.size(), query_distances, reach));
  return kExitOk;
}

}  // namespace

Command add_distance_command(CLI::App& app) {
  auto arguments = std::make_shared<DistanceArguments>();
  DistanceArguments& a = *arguments;
  CLI::App* command = app.add_subcommand("distance", "Geodesic distance from sources to every vertex (and to targets)");
  add_mesh_options(*command, a.mesh);
  add_source_options(*command, a.mesh, a.sources);
  command
      ->add_option("--max-distance", a.max_distance,
                   "Stop the wavefront at this distance; vertices farther away get inf, and so do targets unless "
                   "--targets-beyond exact")
      ->check(distance_check())
      ->type_name("R");
  add_list_option(*command, a.mesh, "--targets", a.targets,
                  "Targets: vertex indices (3,17,42) or points F:b0,b1,b2, separated by spaces, newlines or ';', "
                  "as lists or files; a CSV file with a vertex column (as sample --out s.csv writes) or a .npy "
                  "array of vertex indices of any integer dtype; or - for standard input in any of these forms. "
                  "Propagation stops once they are final; vertex distances are then exact up to the farthest "
                  "target and inf beyond")
      ->type_name("FILE|LIST|-");
  add_list_option(*command, a.mesh, "--target-xyz", a.target_xyz,
                  "Targets at the closest surface points of points in space X,Y,Z (several, repeated, a file "
                  "of x y z lines, or - for standard input), numbered after --targets")
      ->type_name("X,Y,Z|FILE");
  command
      ->add_option("--targets-beyond", a.targets_beyond,
                   "What targets farther than --max-distance get: inf (default; the run stops at the cut-off) or "
                   "exact (the run goes on until every target is final, as gdist and pygeodesic answer; the cut-off "
                   "then applies to vertex distances only)")
      ->check(CLI::IsMember({"inf", "exact"}))
      ->type_name("WHAT");
  add_list_option(*command, a.mesh, "--query-points", a.query_points,
                  "Points whose exact distance is read after the run, in the forms --targets takes: the run keeps "
                  "the windows that reached each face (more memory) and does not stop early for them")
      ->type_name("FILE|LIST|-");
  command->add_flag("--labels", a.labels,
                    "Add the nearest source (index in the order given, vertices first; -1 if none) to each output row");
  add_output_option(*command, "--out", a.out,
                    "Write one distance per vertex in input order: .txt (%.17g, 'inf' if unreachable), "
                    ".csv (vertex,distance; - writes it to stdout), .npy (float64), .ply (the mesh, binary: float "
                    "coordinates, a double distance property and colours; VTK-based tools such as ParaView keep "
                    "only the colours), .ascii.ply (the same as text, the coordinates as doubles too) or .vtk (the "
                    "mesh with the distance as point data, legacy VTK binary, for ParaView, VisIt and pyvista)",
                    kVertexValueFormats, "output");
  add_output_option(*command, "--target-out", a.target_out,
                    "Write one distance per target: .txt, .csv (target,distance; - writes it to stdout) or .npy; "
                    "without it the summary lists them",
                    kTargetValueFormats, "target output");
  add_output_option(*command, "--query-out", a.query_out,
                    "Write one distance per --query-points point: .txt, .csv (point,distance; - writes it to "
                    "stdout) or .npy; without it the summary lists them",
                    kTargetValueFormats, "query output");
  command->add_option("--stats", a.stats, "Write statistics as JSON")->type_name("FILE.json");
  std::vector<std::string> algorithm_names;
  for (const auto& [value, name] : exactgeo::kAlgorithmNames) algorithm_names.emplace_back(name);
  command
      ->add_option("--algorithm", a.algorithm,
                   "Variant (paper Section 5): vtp (default), opvtp (order-preserving merges), ftp (face-sorted "
                   "wavefront), opftp; ftp and opftp run on one thread whatever --threads. All give the same "
                   "distances")
      ->check(CLI::IsMember(algorithm_names))
      ->type_name("NAME");
  command->add_flag("--no-rule1", a.no_rule1,
                    "Ablation: split every window at the opposite vertex instead of pruning with Rule 1");
  command->add_flag("--no-rule23", a.no_rule23, "Ablation: no pairwise pruning of neighbouring windows (Rules 2 and 3)");
  command->add_flag("--timers", a.timers,
                    "Split the propagation time into window propagation, pruning and queue and, with several threads, "
                    "the threads' time into busy, starting, starved and waiting for locks; --stats also gets a "
                    "timeline of the bands (the clock reads slow the run down by up to 60%)");
  add_threads_option(*command, a.threads);
  command->add_flag("--quiet", a.quiet, "No progress line on stderr");
  a.mesh.checks.push_back([&a] {
    const std::array<std::pair<const char*, const std::string*>, 4> outputs = {
        {{"--out", &a.out}, {"--target-out", &a.target_out}, {"--query-out", &a.query_out}, {"--stats", &a.stats}}};
    for (std::size_t i = 0; i < outputs.size(); ++i)
      for (std::size_t j = i + 1; j < outputs.size(); ++j) {
        const std::string &first = *outputs[i].second, &second = *outputs[j].second;
        if (!first.empty() && !second.empty() && same_output(first, second))
          throw CLI::ValidationError(outputs[j].first, std::string(outputs[i].first) + " and " + outputs[j].first +
                                                           " both write to '" + second + "'" +
                                                           (first == second ? "" : " ('" + first + "')") +
                                                           ": give each its own file");
      }
  });
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_distance(*arguments); }};
}

}  // namespace exactgeo::cli
