#pragma once
// Exit codes shared by every executable of the project, and the one place that turns an
// exception into a one-line error message and such a code.

#include <cstddef>
#include <functional>
#include <string>

namespace ihs {

/// Process exit codes (documented in each executable's --help).
enum ExitCode : int {
  kExitOk = 0,           ///< Success.
  kExitInternal = 1,     ///< A bug: an internal check failed or an unexpected exception.
  kExitUsage = 2,        ///< Bad command line, options or configuration.
  kExitInput = 3,        ///< An input file or recording is missing, unreadable or malformed.
  kExitDevice = 4,       ///< The capture device is absent, inaccessible, busy or failed.
  kExitStageFailed = 5,  ///< A processing stage failed; a partial result was saved.
  kExitOutput = 6,       ///< An output could not be written.
};

/// One line for --help listing the codes above.
std::string ExitCodesHelp();

/// `message` on one line: runs of whitespace that hold a line break become "; ", other runs a
/// single space, other control bytes '?'; longer than `kMaxLineBytes`, it is cut there (at a
/// character boundary) and says how much was left out. Text from files and command lines can
/// be echoed through it safely.
inline constexpr std::size_t kMaxLineBytes = 400;
std::string OneLine(const std::string& message);

/// Runs `body` and returns its exit code; an exception escaping it is printed to stderr as one
/// line "<program>: error: <message>" (see OneLine) and mapped to its exit code
/// (std::invalid_argument → kExitUsage, InputError and std::filesystem::filesystem_error →
/// kExitInput, DeviceError → kExitDevice, OutputError → kExitOutput, anything else →
/// kExitInternal).
int RunReportingErrors(const std::string& program, const std::function<int()>& body);

}  // namespace ihs
