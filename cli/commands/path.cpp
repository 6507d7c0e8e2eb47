// exactgeo path: the shortest path from the nearest source to one target, written as a file or printed.
#include <cstdio>
#include <memory>
#include <optional>

#include "command.hpp"
#include "inputs.hpp"
#include "output_options.hpp"

namespace exactgeo::cli {
namespace {

struct PathArguments {
  MeshArguments mesh;
  SourceArguments sources;
  std::string target;
  std::string target_xyz;
  std::string out;
  std::optional<unsigned> threads;
};

int run_path(const PathArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.threads);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const Sources sources = read_sources(arguments.sources, mesh);
  const bool in_space = !arguments.target_xyz.empty();
  const std::vector<exactgeo::SurfacePoint> targets =
      in_space ? locate_listed({arguments.target_xyz}, mesh, "--target-xyz").points
               : parse_targets(arguments.target, mesh, "--target");
  if (targets.size() != 1)
    throw exactgeo::Error(
        exactgeo::ErrorCode::invalid_argument,
        std::string(in_space ? "--target-xyz takes one point" : "--target takes one vertex or point") + ", not " +
            std::to_string(targets.size()));
  exactgeo::GeodesicSolver solver(mesh);
  const exactgeo::GeodesicResult& result = solve(solver, sources, targets, {.threads = threads_for(arguments.threads, mesh)});
  const exactgeo::GeodesicPath path = solver.path_to_target(0);
  if (!arguments.out.empty()) {
    const PathWriter write = find_format(kPathFormats, arguments.out)->write;
    write_file(arguments.out, [&](std::FILE* file) { write(file, path); });
  }
  if (path.points.empty()) {
    // Not mixed into a path written to stdout.
    std::fprintf(arguments.out == kStdout ? stderr : stdout, "target unreachable from every source\n");
    return kExitOk;
  }
  if (arguments.out.empty()) {
    print_table({{"mesh", arguments.mesh.name},
                 {"distance", format_number("%.17g", result.target_distances[0])},
                 {"path length", format_number("%.17g", path.length)},
                 {"points", std::to_string(path.points.size())},
                 {"nearest source", std::to_string(path.source)}});
    for (const auto& p : path.points) std::printf("%.17g %.17g %.17g\n", p[0], p[1], p[2]);
  }
  return kExitOk;
}

}  // namespace

Command add_path_command(CLI::App& app) {
  auto arguments = std::make_shared<PathArguments>();
  CLI::App* command = app.add_subcommand("path", "Shortest path from the nearest source to a target");
  add_mesh_options(*command, arguments->mesh);
  add_source_options(*command, arguments->mesh, arguments->sources);
  CLI::Option* target = command->add_option("--target", arguments->target, "Target vertex index or point F:b0,b1,b2")
                            ->type_name("I|F:b0,b1,b2");
  CLI::Option* target_xyz =
      command
          ->add_option("--target-xyz", arguments->target_xyz,
                       "Target at the closest surface point of a point in space X,Y,Z (instead of --target)")
          ->type_name("X,Y,Z");
  target->excludes(target_xyz);
  arguments->mesh.checks.push_back([command, a = arguments.get()] {
    if (a->target.empty() && a->target_xyz.empty())
      throw CLI::RequiredError(command->get_name() + ": --target or --target-xyz");
  });
  add_threads_option(*command, arguments->threads);
  add_output_option(*command, "--out", arguments->out,
                    "Write the path: .csv (x,y,z and where each point lies; - writes it to stdout), .obj (a "
                    "polyline) or .json; without it the points are printed",
                    kPathFormats, "path");
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_path(*arguments); }};
}

}  // namespace exactgeo::cli
