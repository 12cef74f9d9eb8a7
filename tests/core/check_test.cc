#include "core/check.h"

#include <gtest/gtest.h>

#include <string>

namespace ihs {
namespace {

int evaluations = 0;
int Counted(int value) {
  ++evaluations;
  return value;
}

TEST(CheckTest, ThrowsInternalErrorWithMessageConditionAndLocation) {
  try {
    const int size = 3;
    IHS_CHECK(size > 5, "size is " << size);
    FAIL() << "expected a throw";
  } catch (const InternalError& error) {
    const std::string text = error.what();
    EXPECT_NE(text.find("size is 3"), std::string::npos) << text;
    EXPECT_NE(text.find("size > 5"), std::string::npos) << text;
    EXPECT_NE(text.find("check_test.cc:"), std::string::npos) << text;
  }
}

TEST(CheckTest, ArgumentChecksThrowInvalidArgument) {
  EXPECT_THROW(IHS_CHECK_ARG(1 + 1 == 3, "arithmetic"), std::invalid_argument);
  EXPECT_NO_THROW(IHS_CHECK_ARG(1 + 1 == 2, "arithmetic"));
}

TEST(CheckTest, MessageIsEvaluatedOnlyOnFailure) {
  evaluations = 0;
  IHS_CHECK(true, "value " << Counted(1));
  EXPECT_EQ(evaluations, 0);
  EXPECT_THROW(IHS_CHECK(false, "value " << Counted(2)), InternalError);
  EXPECT_EQ(evaluations, 1);
}

}  // namespace
}  // namespace ihs
