#pragma once
// Command-line parsing shared by every program: CLI11's errors as one line naming the program,
// exit codes as ihs::ExitCode. Include it only from a program's main file (CLI11 is a large
// header).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/exit_codes.h"

namespace ihs {

/// CLI11's help, and for a subcommand that takes its parent's options (CLI11's fallthrough) those
/// options too, under "Global options", before the footer.
class SubcommandHelpFormatter : public CLI::Formatter {
 public:
  std::string make_footer(const CLI::App* app) const override {
    const std::string footer = CLI::Formatter::make_footer(app);
    const CLI::App* parent = app->get_parent();
    if (parent == nullptr || !app->get_fallthrough()) return footer;
    const std::vector<const CLI::Option*> options =
        parent->get_options([parent](const CLI::Option* option) {
          return option->nonpositional() && option != parent->get_help_ptr() &&
                 option != parent->get_help_all_ptr();
        });
    if (options.empty()) return footer;
    // make_group starts with a blank line; make_help has put one before the footer already.
    return make_group("Global options (before or after the command)", false, options).substr(1) +
           "\n" + footer;
  }
};

/// Lets `app`'s own options (--log-level, --quiet, ...) also follow any of its subcommands and
/// lists them in each subcommand's --help. Call once the subcommands are added.
inline void ShareOptionsWithSubcommands(CLI::App& app) {
  const auto formatter = std::make_shared<SubcommandHelpFormatter>();
  for (CLI::App* command : app.get_subcommands({})) {
    command->fallthrough();
    command->formatter(formatter);
  }
}

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
