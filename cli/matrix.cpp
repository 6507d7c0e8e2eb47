// exactgeo matrix: distances from many source vertices to every vertex, one source per thread, written
// block by block (rows: sources, columns: vertices).
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
  std::string sources;
  double max_distance = std::numeric_limits<double>::infinity();
  unsigned threads = 0;
  std::string out;
  bool quiet = false;
};

int run_matrix(const MatrixArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh);
  const exactgeo::Mesh& mesh = loaded.mesh;
  const std::vector<std::uint32_t> sources = parse_vertex_list(list_text(arguments.sources), "--sources");
  exactgeo::MatrixOptions options;
  options.geodesic.max_distance = arguments.max_distance;
  options.threads = arguments.threads;
  Progress progress("rows", sources.size(), arguments.quiet);
  const std::size_t columns = mesh.vertex_count();
  const std::unique_ptr<MatrixWriter> writer =
      find_format(kMatrixFormats, arguments.out)->write(arguments.out, sources.size(), columns);
  exactgeo::for_each_distance_block(mesh, sources, options, [&](std::size_t first, std::span<const double> rows) {
    writer->write_rows(first, rows);
    progress.update(first + rows.size() / columns);
  });
  writer->finish();
  return kExitOk;
}

}  // namespace

Command add_matrix_command(CLI::App& app) {
  auto arguments = std::make_shared<MatrixArguments>();
  CLI::App* command = app.add_subcommand("matrix", "Distances from many source vertices to every vertex, in parallel");
  add_mesh_options(*command, arguments->mesh);
  command
      ->add_option("--sources", arguments->sources,
                   "Source vertices, as a file or a list, separated by spaces, newlines, ',' or ';', or a CSV file with a "
                   "vertex column (as sample --out s.csv writes)")
      ->required()
      ->type_name("FILE|LIST");
  command->add_option("--max-distance", arguments->max_distance, "Cut-off: entries beyond it are inf (or left out)")
      ->check(distance_check())
      ->type_name("R");
  command->add_option("--threads", arguments->threads, "Worker threads (default: one per core; never more than sources)")
      ->check(count_check())
      ->type_name("T");
  add_output_option(*command, "--out", arguments->out,
                    "Write the matrix (rows: sources, columns: vertices): .npy (dense float64), .npz (scipy.sparse "
                    "CSR of the finite entries) or .csv (source,vertex,distance, finite entries)",
                    kMatrixFormats, "matrix")
      ->required();
  command->add_flag("--quiet", arguments->quiet, "No progress line on stderr");
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_matrix(*arguments); }};
}

}  // namespace exactgeo::cli
