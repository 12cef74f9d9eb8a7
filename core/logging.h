#pragma once
// Logging set-up for executables. Code logs through spdlog (included in .cc files only).

#include <string>

namespace ihs {

/// Severity threshold for log output.
enum class LogLevel { kTrace, kDebug, kInfo, kWarn, kError, kOff };

/// Parses "trace", "debug", "info", "warn", "error" or "off" (case-insensitive); throws
/// std::invalid_argument listing the accepted names otherwise.
LogLevel ParseLogLevel(const std::string& name);

/// Sends log lines to stderr as "[level] message" at `level` and above; `quiet` keeps only
/// warnings and errors whatever `level` says. Safe to call again to change the level.
void SetUpLogging(LogLevel level, bool quiet = false);

}  // namespace ihs
