#include "core/logging.h"

#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace ihs {
namespace {

// spdlog's sink for the program's log: each line formatted, then written through a ProgressLine.
class ProgressLineSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit ProgressLineSink(ProgressLine& line) : line_(line) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    spdlog::memory_buf_t text;
    formatter_->format(message, text);
    line_.WriteLog(std::string_view(text.data(), text.size()));
  }
  void flush_() override {}  // ProgressLine flushes every write.

 private:
  ProgressLine& line_;
};

}  // namespace

LogLevel ParseLogLevel(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "trace") return LogLevel::kTrace;
  if (lower == "debug") return LogLevel::kDebug;
  if (lower == "info") return LogLevel::kInfo;
  if (lower == "warn" || lower == "warning") return LogLevel::kWarn;
  if (lower == "error") return LogLevel::kError;
  if (lower == "off") return LogLevel::kOff;
  throw std::invalid_argument("unknown log level '" + name +
                              "' (use trace, debug, info, warn, error or off)");
}

void SetUpLogging(LogLevel level, bool quiet) {
  static const spdlog::level::level_enum kLevels[] = {spdlog::level::trace, spdlog::level::debug,
                                                      spdlog::level::info,  spdlog::level::warn,
                                                      spdlog::level::err,   spdlog::level::off};
  if (quiet) level = std::max(level, LogLevel::kWarn);
  auto logger = spdlog::get("inhandscan");
  if (!logger) {
    logger = std::make_shared<spdlog::logger>(
        "inhandscan", std::make_shared<ProgressLineSink>(ProgressLine::OnStderr()));
    logger->set_pattern("[%l] %v");
    spdlog::set_default_logger(logger);
  }
  logger->set_level(kLevels[static_cast<int>(level)]);
}

void ProgressLine::Show(const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  width_ = std::max(width_, text.size());
  out_ << '\r' << text << std::string(width_ - text.size(), ' ') << std::flush;
  text_ = text;
  shown_ = true;
}

void ProgressLine::End() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shown_) out_ << '\n' << std::flush;
  shown_ = false;
  width_ = 0;
}

void ProgressLine::WriteLog(std::string_view line) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!shown_) {
    out_ << line << std::flush;
    return;
  }
  // Blank the progress line, write the log line from its start, draw the progress line below.
  out_ << '\r' << std::string(width_, ' ') << '\r' << line << text_ << std::flush;
  width_ = text_.size();
}

ProgressLine& ProgressLine::OnStderr() {
  // Never destroyed: a log line may come from a static object's destructor at exit.
  static ProgressLine* const line = new ProgressLine(std::cerr);
  return *line;
}

}  // namespace ihs
