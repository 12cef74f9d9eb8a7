#include "core/logging.h"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

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

// What a terminal shows after `bytes`: '\r' goes back to the line's start, '\n' starts a new
// line, other characters overwrite the one under the cursor. Trailing blanks are dropped.
std::vector<std::string> Screen(const std::string& bytes) {
  std::vector<std::string> lines(1);
  size_t column = 0;
  for (char c : bytes) {
    if (c == '\r') {
      column = 0;
    } else if (c == '\n') {
      lines.emplace_back();
      column = 0;
    } else {
      std::string& line = lines.back();
      if (line.size() <= column) line.resize(column + 1, ' ');
      line[column++] = c;
    }
  }
  for (std::string& line : lines) line.erase(line.find_last_not_of(' ') + 1);
  return lines;
}

using Lines = std::vector<std::string>;

TEST(ProgressLineTest, ALogLineTakesALineOfItsOwnAndTheProgressLineFollowsIt) {
  std::ostringstream out;
  ProgressLine progress(out);
  progress.Show("frames 10/90, 30.0 fps, ETA 3 s");
  progress.WriteLog("[info] saved\n");  // Shorter than the progress line: nothing of it stays.
  EXPECT_EQ(Screen(out.str()), (Lines{"[info] saved", "frames 10/90, 30.0 fps, ETA 3 s"}));
  progress.Show("frames 90/90, 30.0 fps");  // Shorter again: covers the longer one.
  progress.WriteLog("[warn] slow\n");
  progress.End();
  EXPECT_EQ(Screen(out.str()),
            (Lines{"[info] saved", "[warn] slow", "frames 90/90, 30.0 fps", ""}));
}

TEST(ProgressLineTest, WithoutAProgressLineLogLinesPassUnchanged) {
  std::ostringstream out;
  ProgressLine progress(out);
  progress.End();  // Nothing shown: nothing to end.
  progress.WriteLog("[info] a\n");
  progress.WriteLog("[warn] b\n");
  EXPECT_EQ(out.str(), "[info] a\n[warn] b\n");
  progress.Show("frames 1");
  progress.End();
  progress.WriteLog("[info] c\n");  // After End the progress line is not drawn again.
  EXPECT_EQ(Screen(out.str()), (Lines{"[info] a", "[warn] b", "frames 1", "[info] c", ""}));
  EXPECT_EQ(out.str().substr(out.str().size() - 10), "\n[info] c\n");
}

// Threads logging while the progress line changes: every log line arrives whole, on a line of
// its own, and the progress line ends up last.
TEST(ProgressLineTest, LogLinesFromThreadsStayWhole) {
  std::ostringstream out;
  ProgressLine progress(out);
  std::set<std::string> expected;
  std::vector<std::thread> threads;
  for (int t = 0; t < 3; ++t) {
    for (int i = 0; i < 200; ++i) {
      expected.insert("[info] thread " + std::to_string(t) + " line " + std::to_string(i));
    }
    threads.emplace_back([&progress, t] {
      for (int i = 0; i < 200; ++i) {
        progress.WriteLog("[info] thread " + std::to_string(t) + " line " + std::to_string(i) +
                          "\n");
      }
    });
  }
  for (int i = 0; i <= 300; ++i) progress.Show("frames " + std::to_string(i) + "/300");
  for (std::thread& thread : threads) thread.join();
  Lines screen = Screen(out.str());
  ASSERT_EQ(screen.size(), expected.size() + 1);
  EXPECT_EQ(screen.back(), "frames 300/300");
  screen.pop_back();
  EXPECT_EQ(std::set<std::string>(screen.begin(), screen.end()), expected);
}

// The program's log goes through the progress line on stderr.
TEST(ProgressLineTest, SetUpLoggingWritesThroughTheStderrProgressLine) {
  std::ostringstream out;
  std::streambuf* const stderr_buffer = std::cerr.rdbuf(out.rdbuf());
  SetUpLogging(LogLevel::kInfo);
  ProgressLine::OnStderr().Show("frames 5/9, 10.0 fps");
  spdlog::info("export {}", 1);
  spdlog::debug("not shown");
  ProgressLine::OnStderr().End();
  std::cerr.rdbuf(stderr_buffer);
  EXPECT_EQ(Screen(out.str()), (Lines{"[info] export 1", "frames 5/9, 10.0 fps", ""}));
}

}  // namespace
}  // namespace ihs
