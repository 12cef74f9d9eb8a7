// Exceptions become one line on stderr and the documented exit code.

#include "core/exit_codes.h"

#include <gtest/gtest.h>

#include <stdexcept>

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

TEST(ExitCodesTest, EachErrorKindHasItsCode) {
  EXPECT_EQ(RunReportingErrors("t", [] { return 0; }), kExitOk);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw std::invalid_argument("x"); }), kExitUsage);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw InputError("x"); }), kExitInput);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw DeviceError("x\ny"); }), kExitDevice);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw OutputError("x"); }), kExitOutput);
  EXPECT_EQ(RunReportingErrors("t", []() -> int { throw std::runtime_error("x"); }), kExitInternal);
}

}  // namespace
}  // namespace ihs
