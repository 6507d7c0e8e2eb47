// exactgeo sample: geodesic farthest-point sampling of the vertices.
#include <cstdint>
#include <cstdio>
#include <memory>

#include "command.hpp"
#include "inputs.hpp"
#include "outputs.hpp"
#include "progress.hpp"

namespace exactgeo::cli {
namespace {

struct SampleArguments {
  MeshArguments mesh;
  std::size_t count = 0;
  std::uint32_t first = 0;
  std::string out;
  bool quiet = false;
};

int run_sample(const SampleArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh);
  Progress progress("samples", arguments.count, arguments.quiet);
  const exactgeo::Sampling sampling = exactgeo::farthest_point_sampling(
      loaded.mesh, arguments.count, arguments.first, {}, [&](std::size_t done) { progress.update(done); });
  progress.finish();
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
  command->add_option("--first", arguments->first, "The first sample (default 0)")->check(count_check())->type_name("I");
  add_output_option(*command, "--out", arguments->out,
                    "Write the samples: .txt (one vertex per line), .csv (sample,vertex,radius: the distance to "
                    "the samples before) or .npy (int64); without it they are printed",
                    kSamplesFormats, "samples");
  command->add_flag("--quiet", arguments->quiet, "No progress line on stderr");
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_sample(*arguments); }};
}

}  // namespace exactgeo::cli
