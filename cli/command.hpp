// The commands of the exactgeo tool. Each lives in a file of its own in commands/ (distance.cpp, path.cpp, ...)
// that owns its options, registers them on the app and runs the command; main.cpp lists the commands and maps
// errors to exit codes. A new command is one new file and one line in main.cpp's list.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace exactgeo::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 1;
inline constexpr int kExitInvalidInput = 2;
inline constexpr int kExitInternal = 3;
inline constexpr int kExitIncomplete = 4;  // matrix --status: the store has blocks not done yet

inline constexpr const char* kExitCodesHelp =
    "Exit codes: 0 ok, 1 usage error, 2 unreadable or invalid input, 3 internal error.";

// A registered subcommand and what running it does once the arguments are parsed into its options.
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

Command add_distance_command(CLI::App& app);
Command add_path_command(CLI::App& app);
Command add_sample_command(CLI::App& app);
Command add_matrix_command(CLI::App& app);
Command add_info_command(CLI::App& app);
Command add_locate_command(CLI::App& app);
Command add_pairs_command(CLI::App& app);

}  // namespace exactgeo::cli
