// exactgeo matrix: distances from many source vertices to every vertex or to target vertices, one source per
// thread, written block by block (rows: sources, columns: vertices or targets). Into a .zarr store it
// computes one shard of the row blocks (--shard I/N), so that the tasks of a job array fill one store;
// --status says which blocks are done.
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "command.hpp"
#include "inputs.hpp"
#include "output_options.hpp"
#include "progress.hpp"
#include "zarr_store.hpp"

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
  // .zarr stores only.
  std::string shard;  // "I/N"; empty: the whole matrix (0/1)
  bool resume = false;
  std::string dtype = "float32";
  std::size_t block_rows = 0;  // 0: the store's, or the default for a new one
  std::string status;          // --status STORE: report on the store, compute nothing
  bool verify = false;         // with --status or --resume: read the done blocks back and check their sha256
};

int print_store_status(const std::string& store, bool verify) {
  const store::StoreStatus status = store::read_store_status(store, verify);
  const nlohmann::ordered_json& settings = status.settings;
  const nlohmann::ordered_json shape = settings.value("shape", nlohmann::ordered_json::array());
  const nlohmann::ordered_json max_distance = settings.value("max_distance", nlohmann::ordered_json());
  Rows rows = {{"store", std::filesystem::absolute(store).string()},
               {"layout", settings.value("layout", std::string("?"))},
               {"shape", shape.size() == 2 ? shape[0].dump() + " x " + shape[1].dump() : shape.dump()},
               {"dtype", settings.value("dtype", std::string("?"))},
               {"max distance", max_distance.is_null() ? "none" : max_distance.dump()},
               {"block rows", settings.value("block_rows", nlohmann::ordered_json()).dump()},
               {"blocks", std::to_string(status.done.size() + status.missing.size())},
               {"done", std::to_string(status.done.size()) + ": " + block_ranges(status.done)},
               {"missing", std::to_string(status.missing.size()) + ": " + block_ranges(status.missing)}};
  if (verify) {
    std::vector<std::size_t> corrupt;
    for (const store::CorruptBlock& block : status.corrupt) corrupt.push_back(block.block);
    rows.push_back({"corrupt", std::to_string(corrupt.size()) + ": " + block_ranges(corrupt)});
    for (const store::CorruptBlock& block : status.corrupt)
      rows.push_back({"block " + std::to_string(block.block), block.reason});
    std::string names;
    for (const store::DamagedArray& array : status.damaged) names += (names.empty() ? "" : ", ") + array.array;
    rows.push_back({"damaged", std::to_string(status.damaged.size()) + ": " + (names.empty() ? "none" : names)});
    for (const store::DamagedArray& array : status.damaged) rows.push_back({array.array, array.reason});
  }
  print_table(rows);
  return status.complete() ? kExitOk : kExitIncomplete;
}

int run_matrix(const MatrixArguments& arguments) {
  if (!arguments.status.empty()) return print_store_status(arguments.status, arguments.verify);
  const LoadedMesh loaded = load_mesh(arguments.mesh, arguments.threads);
  const exactgeo::Mesh& mesh = loaded.mesh;
  // Read and checked before the output is created, so that a bad vertex leaves an existing file as it was.
  const std::vector<std::uint32_t> sources =
      read_vertex_list(arguments.sources, mesh, "--sources", VertexCheck::used_by_a_face);
  exactgeo::MatrixOptions options;
  options.geodesic.max_distance = arguments.max_distance;
  options.threads = arguments.threads;
  if (!arguments.targets.empty())
    options.target_vertices = read_vertex_list(arguments.targets, mesh, "--targets", VertexCheck::in_range);
  const std::size_t columns = options.target_vertices ? options.target_vertices->size() : mesh.vertex_count();
  std::span<const std::uint32_t> targets;
  if (options.target_vertices) targets = *options.target_vertices;
  StoreRequest store{.mesh = &mesh,
                     .weld = arguments.mesh.weld,
                     .max_distance = std::nullopt,
                     .dtype = arguments.dtype,
                     .block_rows = arguments.block_rows,
                     .shard = arguments.shard.empty() ? Shard{} : parse_shard(arguments.shard),
                     .resume = arguments.resume,
                     .verify = arguments.verify,
                     .quiet = arguments.quiet};
  if (std::isfinite(arguments.max_distance)) store.max_distance = arguments.max_distance;
  const std::unique_ptr<MatrixWriter> writer =
      find_format(kMatrixFormats, arguments.out)->write(arguments.out, {sources, targets, columns}, store);
  const std::vector<RowRange> ranges = writer->row_ranges(sources.size());
  std::size_t rows_wanted = 0, rows_done = 0;
  for (const RowRange& range : ranges) rows_wanted += range.end - range.first;
  Progress progress("rows", rows_wanted, arguments.quiet);
  for (const RowRange& range : ranges) {
    const auto range_sources = std::span(sources).subspan(range.first, range.end - range.first);
    if (store.max_distance) {  // a row costs what its run reaches, not the mesh's size
      exactgeo::for_each_sparse_block(mesh, range_sources, options,
                                      [&](std::size_t first, const exactgeo::SparseDistances& block) {
                                        writer->write_sparse_rows(range.first + first, block);
                                        rows_done += block.rows;
                                        progress.update(rows_done);
                                      });
      continue;
    }
    exactgeo::for_each_distance_block(mesh, range_sources, options, [&](std::size_t first, std::span<const double> rows) {
      writer->write_rows(range.first + first, rows);
      rows_done += columns ? rows.size() / columns : 0;
      progress.update(rows_done);
    });
  }
  progress.finish();
  writer->finish();
  return kExitOk;
}

// A check for --shard: "I/N" with I below N.
const CLI::Validator& shard_check() {
  static const CLI::Validator check(
      [](std::string& text) -> std::string {
        try {
          parse_shard(text);
        } catch (const std::invalid_argument& e) {
          return e.what();
        }
        return {};
      },
      "", "shard");
  return check;
}

}  // namespace

Command add_matrix_command(CLI::App& app) {
  auto arguments = std::make_shared<MatrixArguments>();
  CLI::App* command = app.add_subcommand(
      "matrix", "Distances from many source vertices to every vertex (or to target vertices), in parallel");
  add_mesh_options(*command, arguments->mesh);
  CLI::Option* sources = add_list_option(
      *command, arguments->mesh, "--sources", arguments->sources,
      "Source vertices (the rows): lists (0,5 9), files (indices separated by spaces, newlines, ',' or ';'; a "
      "CSV file with a vertex column, as sample --out s.csv writes; a .npy array of any integer dtype, as "
      "sample --out s.npy writes) or - for standard input in any of these forms (sample ... --out - | matrix "
      "... --sources -)")->type_name("FILE|LIST|-");
  CLI::Option* targets =
      add_list_option(*command, arguments->mesh, "--targets", arguments->targets,
                      "Target vertices (the columns, in their order; default every vertex), in the same forms; each "
                      "run stops once they are final. A vertex no face uses is inf, as in the full matrix")
          ->type_name("FILE|LIST|-");
  CLI::Option* max_distance =
      command->add_option("--max-distance", arguments->max_distance,
                          "Cut-off: entries beyond it are inf (or left out), targets too (leave it out to have every "
                          "target's distance)")
          ->check(distance_check())
          ->type_name("R");
  CLI::Option* threads =
      command->add_option("--threads", arguments->threads, "Worker threads (0, the default: one per core; never more than sources)")
          ->check(count_check(std::numeric_limits<unsigned>::max()))
          ->type_name("T");
  CLI::Option* out = add_output_option(
      *command, "--out", arguments->out,
      "Write the matrix (rows: sources, columns: vertices or targets): .npy (dense float64, the "
      "matrix alone), .npz (scipy.sparse CSR of the finite entries, with arrays sources and targets "
      "naming the rows' and columns' vertices), .csv (source,vertex,distance or with targets "
      "source,target,distance: row and column numbers of the finite entries; - writes it to stdout) or .zarr "
      "(a Zarr store folder, the layout exactgeo.distributed writes: dense, or with --max-distance CSR pieces per "
      "block of rows; several processes can fill it, see --shard)",
      kMatrixFormats, "matrix");
  CLI::Option* shard =
      command->add_option("--shard", arguments->shard,
                          ".zarr: compute the I-th of N interleaved sets of row blocks (blocks B with B % N == I), "
                          "e.g. --shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT; the N shards, run in any "
                          "order, at the same time or not, fill the store (default 0/1: every block)")
          ->check(shard_check())
          ->type_name("I/N");
  CLI::Option* resume = command->add_flag(
      "--resume", arguments->resume,
      ".zarr: skip the blocks already marked done in the store (without it, the shard's blocks are computed "
      "again and replaced whole)");
  CLI::Option* dtype = command->add_option("--dtype", arguments->dtype,
                                           ".zarr: float32 (default: the float64 distances rounded) or float64")
                           ->check(CLI::IsMember({"float32", "float64"}).description(""))
                           ->type_name("float32|float64");
  CLI::Option* block_rows =
      command->add_option("--block-rows", arguments->block_rows,
                          ".zarr: rows per block, each one chunk and one marker (default: the store's; for a new "
                          "store at most 32 MiB a chunk, 4096 rows, some 32 blocks or more)")
          ->check(count_check())
          ->type_name("B");
  command->add_flag("--quiet", arguments->quiet, "No progress line and no summary on stderr");
  command->add_option("--status", arguments->status,
                          "Report which blocks of the store are done and which are missing, then exit (0: every "
                          "block done, 4: some missing); computes nothing")
          ->type_name("STORE.zarr");
  CLI::Option* verify = command->add_flag(
      "--verify", arguments->verify,
      "With --status or --resume: read each block marked done back and check it against the sha256 its marker "
      "recorded, and the source, target and mesh arrays against the store's settings; --status reports the blocks "
      "that differ as corrupt (and missing) and the arrays as damaged, --resume computes the blocks again and "
      "rewrites the arrays");
  MatrixArguments* a = arguments.get();
  a->mesh.mesh_unused = [a] { return !a->status.empty(); };
  const std::vector<CLI::Option*> computing = {sources, targets, max_distance, threads, out, shard, resume, dtype,
                                               block_rows};
  a->mesh.checks.push_back([a, computing, shard, resume, dtype, block_rows, verify] {
    if (verify->count() && a->status.empty() && !a->resume)
      throw CLI::ValidationError("--verify", "checks a store's done blocks: use it with --status or --resume");
    if (!a->status.empty()) {
      if (!a->mesh.name.empty()) throw CLI::ValidationError("--status", "takes a store alone, not a MESH");
      for (CLI::Option* option : computing)
        if (option->count()) throw CLI::ValidationError("--status", "takes a store alone, not " + option->get_name());
      return;
    }
    if (a->sources.empty()) throw CLI::RequiredError("--sources");
    if (a->out.empty()) throw CLI::RequiredError("--out");
    if (block_rows->count() && a->block_rows == 0) throw CLI::ValidationError("--block-rows", "must be at least 1");
    if (has_extension(a->out, ".zarr")) return;
    for (CLI::Option* store_only : {shard, resume, dtype, block_rows})
      if (store_only->count())
        throw CLI::ValidationError(store_only->get_name(), "applies to .zarr stores only, not '" + a->out + "'");
  });
  command->footer(std::string(kExitCodesHelp) + " matrix --status: 0 when every block is done, " +
                  std::to_string(kExitIncomplete) + " when some are missing (with --verify: or corrupt, or an array "
                  "damaged).");
  return {command, [arguments] { return run_matrix(*arguments); }};
}

}  // namespace exactgeo::cli
