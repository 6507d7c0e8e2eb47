// exactgeo: command-line front end, a thin layer over the public API. This file sets up the app, hands the
// arguments to the command the user named, and maps errors to the exit codes of kExitCodesHelp.
#include <CLI/CLI.hpp>

#include <array>
#include <cstdio>
#include <new>
#include <string>
#include <string_view>

#include "command.hpp"
#include "exactgeo/error.hpp"
#include "exactgeo/version.hpp"
#include "outputs.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace {

using namespace exactgeo::cli;

void print_error(std::string_view message) {
  std::fprintf(stderr, "exactgeo: %.*s\n", int(message.size()), message.data());
}

int usage_error(std::string_view message) {
  print_error(message);
  std::fprintf(stderr, "Run 'exactgeo --help' for usage.\n");
  return kExitUsage;
}

// Arrays of 4 MB and more (a mesh's, the engine's, the build's scratch) are mapped from the system one by one
// and given back when freed: the library maps them itself, in huge pages (mesh_memory.cpp), and this
// threshold makes glibc do the same for other arrays that large. glibc would otherwise raise its mapping
// threshold after the first such array is freed and carve later ones from its heap, where what the build
// frees still counts against the run's memory. Smaller arrays stay on the heap, which hands what the build
// freed to the next array without faulting in fresh pages: with a 1 MB threshold, nefertiti's build took
// 15% longer and its read 17% longer, for 0.9% less peak memory.
void map_large_arrays_apart() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 4 << 20);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  map_large_arrays_apart();
  CLI::App app{"exactgeo: exact geodesic distances on triangle meshes (VTP algorithm)", "exactgeo"};
  app.set_version_flag("--version", std::string("exactgeo ") + exactgeo::kVersion);
  app.require_subcommand(1);
  app.footer(kExitCodesHelp);
  const std::array commands = {add_distance_command(app), add_path_command(app), add_sample_command(app),
                               add_matrix_command(app), add_info_command(app), add_locate_command(app),
                               add_pairs_command(app)};

  // CLI11 reports a mistyped command only as "A subcommand is required"; name it instead.
  std::string names;
  bool known = false;
  for (const Command& command : commands) {
    names += (names.empty() ? "" : ", ") + command.app->get_name();
    known = known || (argc > 1 && command.app->get_name() == argv[1]);
  }
  if (argc > 1 && argv[1][0] != '-' && !known)
    return usage_error(std::string("unknown command '") + argv[1] + "' (use " + names + ")");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    return usage_error(e.what());
  }

  remove_unfinished_outputs_on_interrupt();
  try {
    for (const Command& command : commands)
      if (command.app->parsed()) return command.run();
    return kExitUsage;  // unreachable: require_subcommand(1) rejects a command line without one
  } catch (const exactgeo::Error& e) {
    if (e.code() == exactgeo::ErrorCode::internal) {
      print_error(std::string("internal error: ") + e.what());
      return kExitInternal;
    }
    print_error(e.what());
    return kExitInvalidInput;
  } catch (const std::bad_alloc&) {
    print_error("out of memory");
    return kExitInternal;
  } catch (const std::exception& e) {
    print_error(std::string("internal error: ") + e.what());
    return kExitInternal;
  }
}
