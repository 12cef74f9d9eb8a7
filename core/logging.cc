#include "core/logging.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

namespace ihs {

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
    logger = spdlog::stderr_logger_mt("inhandscan");
    logger->set_pattern("[%l] %v");
    spdlog::set_default_logger(logger);
  }
  logger->set_level(kLevels[static_cast<int>(level)]);
}

}  // namespace ihs
