// exactgeo info: what validation found in a mesh (MeshReport), as aligned text or JSON.
#include <cstdio>
#include <memory>

#include "command.hpp"
#include "inputs.hpp"
#include "report_fields.hpp"

namespace exactgeo::cli {
namespace {

struct InfoArguments {
  MeshArguments mesh;
  bool json = false;
};

int run_info(const InfoArguments& arguments) {
  const LoadedMesh loaded = load_mesh(arguments.mesh);
  const exactgeo::MeshReport& report = loaded.mesh.report();
  if (arguments.json) {
    nlohmann::ordered_json json;
    json["mesh"] = arguments.mesh.name;
    json.update(report_json(report));
    std::printf("%s\n", json_text(json).c_str());
  } else {
    Rows rows = {{"mesh", arguments.mesh.name}};
    for (auto& row : report_rows(report)) rows.push_back(std::move(row));
    print_table(rows);
  }
  return kExitOk;
}

}  // namespace

Command add_info_command(CLI::App& app) {
  auto arguments = std::make_shared<InfoArguments>();
  CLI::App* command = app.add_subcommand("info", "What validation found in a mesh");
  add_mesh_options(*command, arguments->mesh);
  command->add_flag("--json", arguments->json, "Print JSON instead of aligned text");
  command->footer(kExitCodesHelp);
  return {command, [arguments] { return run_info(*arguments); }};
}

}  // namespace exactgeo::cli
