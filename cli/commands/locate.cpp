// exactgeo locate: the closest surface point of points in space, as a face and barycentric coordinates (what
// --source-point and --targets take), where it lies, and the distance to it.
#include <array>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include "command.hpp"
#include "inputs.hpp"
#include "output_options.hpp"

namespace exactgeo::cli {
namespace {

struct LocateArguments {
  MeshArguments mesh;
  std::vector<std::string> points;
  std::string out;
  unsigned threads = 0;
};

int run_locate(const LocateArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.threads);
  const exactgeo::LocateResult located = locate_listed(arguments.points, loaded.mesh, "--points", arguments.threads);
  std::vector<std::array<double, 3>> positions;
  positions.reserve(located.points.size());
  for (const exactgeo::SurfacePoint& point : located.points)
    positions.push_back(exactgeo::point_position(loaded.mesh, point));
  const LocatedPoints rows = {located.points, positions, located.distances};
  // Without a file, the CSV on stdout.
  const std::string out = arguments.out.empty() ? std::string(kStdout) : arguments.out;
  const LocatedWriter write = find_format(kLocatedFormats, out)->write;
  write_file(out, [&](std::FILE* file) { write(file, rows); });
  return kExitOk;
}

}  // namespace

Command add_locate_command(CLI::App& app) {
  auto arguments = std::make_shared<LocateArguments>();
  CLI::App* command =
      app.add_subcommand("locate", "Closest surface points of points in space, as faces and barycentric coordinates");
  add_mesh_options(*command, arguments->mesh);
  add_list_option(*command, arguments->mesh, "--points", arguments->points,
                  "Points in space X,Y,Z (several, repeated, or files of x y z lines, as .xyz point clouds and "
                  "x,y,z CSV files have them)")
      ->required()
      ->type_name("X,Y,Z|FILE");
  add_output_option(*command, "--out", arguments->out,
                    "Write the points: .txt (F:b0,b1,b2 per line, as --targets and --source-point take them) or "
                    ".csv (point,face,b0,b1,b2,x,y,z,distance: the face and barycentric coordinates of the closest "
                    "surface point, where it lies, and its distance); without it the CSV goes to stdout",
                    kLocatedFormats, "output");
  command
      ->add_option("--threads", arguments->threads,
                   "Threads reading and building the mesh and sharing the points (0, the default: one per core); "
                   "the result is the same on any count")
      ->check(count_check(std::numeric_limits<unsigned>::max()))
      ->type_name("N");
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_locate(*arguments); }};
}

}  // namespace exactgeo::cli
