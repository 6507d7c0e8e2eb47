// exactgeo sample: geodesic farthest-point sampling of the vertices.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "command.hpp"
#include "inputs.hpp"
#include "output_options.hpp"
#include "progress.hpp"

namespace exactgeo::cli {
namespace {

struct SampleArguments {
  MeshArguments mesh;
  std::size_t count = 0;
  std::vector<std::string> first;  // vertex indices, syntax checked while parsing
  std::string out;
  bool quiet = false;
};

int run_sample(const SampleArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh);
  std::vector<std::uint32_t> first;
  for (const std::string& text : arguments.first) first.push_back(parse_vertex_list(text, "--first").front());
  if (first.empty()) first.push_back(0);
  // Samples are distinct vertices (but for repeated --first ones): say so before any work.
  if (arguments.count > std::max(loaded.mesh.vertex_count(), first.size()))
    throw exactgeo::Error(exactgeo::ErrorCode::invalid_argument,
                          "--count " + std::to_string(arguments.count) + " exceeds the mesh's " +
                              std::to_string(loaded.mesh.vertex_count()) +
                              " vertices: farthest-point samples are distinct vertices");
  Progress progress("samples", arguments.count, arguments.quiet);
  const exactgeo::Sampling sampling = exactgeo::farthest_point_sampling(
      loaded.mesh, arguments.count, first, {}, [&](std::size_t done) { progress.update(done); });
  progress.finish();
  if (sampling.samples.size() < arguments.count)
    std::fprintf(stderr,
                 "exactgeo: warning: %zu of the %zu samples asked for: every vertex within reach of the first "
                 "samples is one (the mesh has %zu vertices; the rest lie on other pieces or are unused)\n",
                 sampling.samples.size(), arguments.count, loaded.mesh.vertex_count());
  // Without a file, one sample per line, as .txt has them.
  const SamplesWriter write = arguments.out.empty() ? kSamplesFormats[0].write : find_format(kSamplesFormats, arguments.out)->write;
  if (arguments.out.empty()) {
    write(stdout, sampling);
  } else {
    write_file(arguments.out, [&](std::FILE* file) { write(file, sampling); });
  }
  return kExitOk;
}

}  // namespace

Command add_sample_command(CLI::App& app) {
  auto arguments = std::make_shared<SampleArguments>();
  CLI::App* command = app.add_subcommand("sample", "Geodesic farthest-point sampling of the vertices");
  add_mesh_options(*command, arguments->mesh);
  command->add_option("-k,--count", arguments->count, "Number of samples")->required()->check(count_check())->type_name("N");
  add_list_option(*command, arguments->mesh, "--first", arguments->first,
                  "The first samples, taken in their order (default 0), then the farthest points")
      ->type_name("I");
  add_output_option(*command, "--out", arguments->out,
                    "Write the samples: .txt (one vertex per line), .csv (sample,vertex,radius: the distance to "
                    "the samples before) or .npy (int64); without it they are printed",
                    kSamplesFormats, "samples");
  command->add_flag("--quiet", arguments->quiet, "No progress line on stderr");
  arguments->mesh.checks.push_back([a = arguments.get()] {
    for (const std::string& text : a->first)
      if (!count_check()(std::string(text)).empty())
        throw CLI::ValidationError("--first", "'" + text + "' is not a vertex index");
  });
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_sample(*arguments); }};
}

}  // namespace exactgeo::cli
