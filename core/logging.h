#pragma once
// Logging set-up for executables. Code logs through spdlog (included in .cc files only).

#include <cstddef>
#include <mutex>
#include <ostream>
#include <string>
#include <string_view>

namespace ihs {

/// Severity threshold for log output.
enum class LogLevel { kTrace, kDebug, kInfo, kWarn, kError, kOff };

/// Parses "trace", "debug", "info", "warn", "error" or "off" (case-insensitive); throws
/// std::invalid_argument listing the accepted names otherwise.
LogLevel ParseLogLevel(const std::string& name);

/// Sends log lines to stderr as "[level] message" at `level` and above, through
/// ProgressLine::OnStderr(); `quiet` keeps only warnings and errors whatever `level` says. Safe to
/// call again to change the level.
void SetUpLogging(LogLevel level, bool quiet = false);

/// The one line a program rewrites in place on a terminal (its progress), and the log lines
/// written meanwhile: a log line clears the progress line first and the progress line is drawn
/// again below it, so the two never share a line. Thread-safe: stages log from their threads.
class ProgressLine {
 public:
  explicit ProgressLine(std::ostream& out) : out_(out) {}

  /// Draws `text` over the progress line ("\r", then blanks over what a longer line left).
  void Show(const std::string& text);
  /// Ends the progress line with a newline, so it stays on screen above what follows; nothing
  /// when none is shown.
  void End();
  /// Writes one whole log line (ending in '\n') on a line of its own.
  void WriteLog(std::string_view line);

  /// The process's progress line on stderr (std::cerr), which SetUpLogging's log lines go through.
  static ProgressLine& OnStderr();

 private:
  std::mutex mutex_;
  std::ostream& out_;
  bool shown_ = false;
  std::string text_;  // The progress line's text while shown.
  size_t width_ = 0;  // Columns the progress line has covered since it was last ended.
};

}  // namespace ihs
