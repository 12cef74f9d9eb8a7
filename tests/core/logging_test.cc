#include "core/logging.h"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <stdexcept>

namespace ihs {
namespace {

TEST(LoggingTest, ParsesLevelNamesCaseInsensitively) {
  EXPECT_EQ(ParseLogLevel("trace"), LogLevel::kTrace);
  EXPECT_EQ(ParseLogLevel("DEBUG"), LogLevel::kDebug);
  EXPECT_EQ(ParseLogLevel("Info"), LogLevel::kInfo);
  EXPECT_EQ(ParseLogLevel("warning"), LogLevel::kWarn);
  EXPECT_EQ(ParseLogLevel("error"), LogLevel::kError);
  EXPECT_EQ(ParseLogLevel("off"), LogLevel::kOff);
}

TEST(LoggingTest, RejectsUnknownLevelsNamingTheChoices) {
  try {
    ParseLogLevel("loud");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'loud'"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("warn"), std::string::npos);
  }
}

TEST(LoggingTest, SetUpSetsTheDefaultLoggerLevelAndQuietKeepsWarnings) {
  SetUpLogging(LogLevel::kDebug);
  EXPECT_EQ(spdlog::default_logger()->name(), "inhandscan");
  EXPECT_EQ(spdlog::default_logger()->level(), spdlog::level::debug);
  SetUpLogging(LogLevel::kInfo, /*quiet=*/true);
  EXPECT_EQ(spdlog::default_logger()->level(), spdlog::level::warn);
  SetUpLogging(LogLevel::kError, /*quiet=*/true);
  EXPECT_EQ(spdlog::default_logger()->level(), spdlog::level::err);
}

}  // namespace
}  // namespace ihs
