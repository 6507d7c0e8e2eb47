// exactgeo pairs: the exact distance between each of a list of pairs of points, each pair from a search of its
// own that heads for its second point and stops once nothing left can reach it shorter (docs/pairs.md).
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "inputs.hpp"
#include "output_options.hpp"

namespace exactgeo::cli {
namespace {

struct PairsArguments {
  MeshArguments mesh;
  std::vector<std::string> pairs;
  double max_distance = std::numeric_limits<double>::infinity();
  unsigned threads = 0;
  std::string out;
};

int run_pairs(const PairsArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.threads);
  const Pairs pairs = read_pairs(arguments.pairs, loaded.mesh, "--pairs");
  const exactgeo::PairResult result = exactgeo::pair_distances(
      loaded.mesh, pairs.a, pairs.b,
      {.geodesic = {.max_distance = arguments.max_distance}, .threads = arguments.threads});
  // Without a file, the CSV on stdout.
  const std::string out = arguments.out.empty() ? std::string(kStdout) : arguments.out;
  write_values(out, kTargetValueFormats, {result.distances, {}, "pair", nullptr});
  return kExitOk;
}

}  // namespace

Command add_pairs_command(CLI::App& app) {
  auto arguments = std::make_shared<PairsArguments>();
  CLI::App* command = app.add_subcommand(
      "pairs", "Distances between given pairs of points, each without a full run, the pairs spread over the cores");
  add_mesh_options(*command, arguments->mesh);
  add_list_option(*command, arguments->mesh, "--pairs", arguments->pairs,
                  "Pairs of points: lists (\"0,5; 7 12:0.2,0.3,0.5\": pairs separated by ';'), files of one pair "
                  "per line (two vertex indices or points F:b0,b1,b2, as --targets takes them, separated by a space, "
                  "or by a comma between vertex indices; a CSV header such as a,b is skipped), a .npy array of shape "
                  "(n, 2) of vertex indices of any integer dtype, or - for standard input in any of these forms")
      ->required()
      ->type_name("FILE|LIST|-");
  command
      ->add_option("--max-distance", arguments->max_distance,
                   "Pairs farther apart than this get inf, and each search stops there")
      ->check(distance_check())
      ->type_name("R");
  command
      ->add_option("--threads", arguments->threads,
                   "Threads reading and building the mesh and sharing the pairs, one search each (0, the default: "
                   "one per core); the distances are the same on any count")
      ->check(count_check(std::numeric_limits<unsigned>::max()))
      ->type_name("N");
  add_output_option(*command, "--out", arguments->out,
                    "Write the distances, one per pair in their order (inf where unreachable or beyond "
                    "--max-distance): .txt (one per line), .csv (pair,distance) or .npy (float64); without it the "
                    "CSV goes to stdout",
                    kTargetValueFormats, "output");
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_pairs(*arguments); }};
}

}  // namespace exactgeo::cli
