// exactgeo matrix: distances from many source vertices to every vertex or to target vertices, one source per
// thread, written block by block (rows: sources, columns: vertices or targets).
#include <limits>
#include <memory>

#include "command.hpp"
#include "inputs.hpp"
#include "outputs.hpp"
#include "progress.hpp"

namespace exactgeo::cli {
namespace {

struct MatrixArguments {
  MeshArguments mesh;
  std::vector<std::string> sources;
  std::vector<std::string> targets;
  double max_distance = std::numeric_limits<double>::infinity();
  unsigned threads = 0;
  std::string out;
  bool quiet = false;
};

int run_matrix(const MatrixArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const std::vector<std::uint32_t> sources = parse_vertex_list(arguments.sources, "--sources");
  exactgeo::MatrixOptions options;
  options.geodesic.max_distance = arguments.max_distance;
  options.threads = arguments.threads;
  if (!arguments.targets.empty()) options.target_vertices = parse_vertex_list(arguments.targets, "--targets");
  Progress progress("rows", sources.size(), arguments.quiet);
  const std::size_t columns = options.target_vertices ? options.target_vertices->size() : mesh.vertex_count();
  std::span<const std::uint32_t> targets;
  if (options.target_vertices) targets = *options.target_vertices;
  // Checked before the output is created, so that a bad vertex leaves an existing file as it was.
  for (std::uint32_t v : targets) exactgeo::vertex_point(mesh, v);
  const std::unique_ptr<MatrixWriter> writer =
      find_format(kMatrixFormats, arguments.out)->write(arguments.out, {sources, targets, columns});
  exactgeo::for_each_distance_block(mesh, sources, options, [&](std::size_t first, std::span<const double> rows) {
    writer->write_rows(first, rows);
    progress.update(first + (columns ? rows.size() / columns : 0));
  });
  writer->finish();
  return kExitOk;
}

}  // namespace

Command add_matrix_command(CLI::App& app) {
  auto arguments = std::make_shared<MatrixArguments>();
  CLI::App* command = app.add_subcommand(
      "matrix", "Distances from many source vertices to every vertex (or to target vertices), in parallel");
  add_mesh_options(*command, arguments->mesh);
  add_list_option(*command, arguments->mesh, "--sources", arguments->sources,
                  "Source vertices (the rows), as files or lists, separated by spaces, newlines, ',' or ';', or a CSV "
                  "file with a vertex column (as sample --out s.csv writes)")
      ->required()
      ->type_name("FILE|LIST");
  add_list_option(*command, arguments->mesh, "--targets", arguments->targets,
                  "Target vertices (the columns, in their order; default every vertex), in the same forms; each "
                  "run stops once they are final")
      ->type_name("FILE|LIST");
  command->add_option("--max-distance", arguments->max_distance,
                      "Cut-off: entries beyond it are inf (or left out), targets too (leave it out to have every "
                      "target's distance)")
      ->check(distance_check())
      ->type_name("R");
  command->add_option("--threads", arguments->threads, "Worker threads (default: one per core; never more than sources)")
      ->check(count_check())
      ->type_name("T");
  add_output_option(*command, "--out", arguments->out,
                    "Write the matrix (rows: sources, columns: vertices or targets): .npy (dense float64, the "
                    "matrix alone), .npz (scipy.sparse CSR of the finite entries, with arrays sources and targets "
                    "naming the rows' and columns' vertices) or .csv (source,vertex,distance or with targets "
                    "source,target,distance: row and column numbers of the finite entries; - writes it to stdout)",
                    kMatrixFormats, "matrix")
      ->required();
  command->add_flag("--quiet", arguments->quiet, "No progress line on stderr");
  arguments->mesh.checks.push_back([a = arguments.get()] {
    if (a->sources.empty()) throw CLI::RequiredError("--sources");
  });
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_matrix(*arguments); }};
}

}  // namespace exactgeo::cli
