#pragma once
// Command-line parsing shared by every program: CLI11's errors as one line naming the program,
// exit codes as ihs::ExitCode. Include it only from a program's main file (CLI11 is a large
// header).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>

#include "core/exit_codes.h"

namespace ihs {

/// Parses `argv` into `app`. Returns the exit code when the program should end now: 0 after
/// --help or --version (printed), kExitUsage after a bad command line (one line on stderr:
/// "NAME: error: WHAT (see --help)"); nothing when it should go on.
inline std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);
    std::fprintf(stderr, "%s: error: %s (see --help)\n", app.get_name().c_str(), error.what());
    return kExitUsage;
  }
  return std::nullopt;
}

}  // namespace ihs
