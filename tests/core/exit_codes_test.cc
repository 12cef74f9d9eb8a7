// Exceptions become one line on stderr and the documented exit code.

#include "core/exit_codes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "core/errors.h"

namespace ihs {
namespace {

TEST(ExitCodesTest, MessagesBecomeOneLine) {
  EXPECT_EQ(
      OneLine("cannot open the camera: \tno devices found\n\nNo PrimeSense device on the bus."),
      "cannot open the camera: no devices found; No PrimeSense device on the bus.");
  EXPECT_EQ(OneLine("  plain  message \n"), "plain message");
  EXPECT_EQ(OneLine(""), "");
}

TEST(ExitCodesTest, ControlBytesAreReplacedAndLongTextIsCut) {
  // A recording's header bytes echoed in an error: the terminal gets no escape sequence.
  EXPECT_EQ(OneLine("bad name \x1b[2J(\x07)(\x7f)"), "bad name ?[2J(?)(?)");
  // A 5 MB config line is cut, at a character boundary, and says so.
  const std::string long_text = "value " + std::string(5'000'000, 'x');
  const std::string line = OneLine(long_text);
  EXPECT_LT(line.size(), kMaxLineBytes + 40);
  EXPECT_NE(line.find("[4999606 more bytes]"), std::string::npos) << line.substr(380);
  std::string accents;
  for (int i = 0; i < 300; ++i) accents += "\xc2\xb0";  // "°" × 300: 600 bytes.
  const std::string cut = OneLine(accents);
  EXPECT_EQ(cut.substr(0, kMaxLineBytes), accents.substr(0, kMaxLineBytes));
  EXPECT_EQ(cut.substr(kMaxLineBytes, 2), " [");
}

TEST(ExitCodesTest, EachErrorKindHasItsCode) {
  EXPECT_EQ(RunReportingErrors("t", [] { return 0; }), kExitOk);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw std::invalid_argument("x"); }), kExitUsage);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw InputError("x"); }), kExitInput);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw DeviceError("x\ny"); }), kExitDevice);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw OutputError("x"); }), kExitOutput);
  // A symlink loop met by std::filesystem before any reader: the input is unreadable.
  EXPECT_EQ(
      RunReportingErrors("t",
                         []() -> int {
                           throw std::filesystem::filesystem_error(
                               "status", "loop",
                               std::make_error_code(std::errc::too_many_symbolic_link_levels));
                         }),
      kExitInput);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw std::runtime_error("x"); }), kExitInternal);
}

}  // namespace
}  // namespace ihs
