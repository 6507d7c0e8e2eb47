// The command-line options that name an output file: kept apart from outputs.hpp, so that the files
// writing outputs do not compile the command-line parser.
#pragma once

#include <CLI/CLI.hpp>

#include <span>
#include <string>

#include "outputs.hpp"

namespace exactgeo::cli {

// Adds an output option to `command` that accepts the table's extensions (a usage error otherwise); `what`
// names the output in the message: "unsupported WHAT file 'x.xyz': the extension must be .txt or .csv".
template <class Writer>
CLI::Option* add_output_option(CLI::App& command, const std::string& name, std::string& path,
                               const std::string& help, std::span<const Format<Writer>> formats,
                               const std::string& what) {
  const auto [type_name, extensions] = format_names(formats);
  // `extensions` is copied by an init-capture: Clang before 16 cannot capture a structured binding.
  const CLI::Validator check(
      [formats, what, extensions = extensions](std::string& file) -> std::string {
        if (find_format(formats, file)) return {};
        return "unsupported " + what + " file '" + file + "': the extension must be " + extensions;
      },
      "", what);
  return command.add_option(name, path, help)->check(check)->type_name(type_name);
}

}  // namespace exactgeo::cli
