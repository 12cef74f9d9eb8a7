#include "core/frame.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace ihs {
namespace {

TEST(FrameTest, BlankFrameHasTheRequestedSizeAndNoValidDepth) {
  const Frame frame = Frame::Blank(640, 480);
  EXPECT_EQ(frame.PixelCount(), 307200);
  EXPECT_EQ(frame.depth_mm.size(), 307200u);
  EXPECT_EQ(frame.rgb.size(), 921600u);
  EXPECT_TRUE(frame.HasColor());
  EXPECT_EQ(frame.ValidDepthCount(), 0);
  EXPECT_NO_THROW(frame.Check());
  EXPECT_FALSE(Frame::Blank(4, 3, false).HasColor());
}

TEST(FrameTest, DepthAtIsRowMajor) {
  Frame frame = Frame::Blank(4, 3);
  frame.depth_mm[2 * 4 + 1] = 750;  // u = 1, v = 2.
  EXPECT_EQ(frame.DepthAt(1, 2), 750);
  EXPECT_EQ(frame.DepthAt(2, 1), 0);
  EXPECT_EQ(frame.ValidDepthCount(), 1);
}

TEST(FrameTest, CheckRejectsInconsistentSizes) {
  Frame frame = Frame::Blank(4, 3);
  frame.depth_mm.pop_back();
  EXPECT_THROW(frame.Check(), InputError);
  frame = Frame::Blank(4, 3);
  frame.rgb.resize(5);
  EXPECT_THROW(frame.Check(), InputError);
  frame = Frame::Blank(4, 3);
  frame.width = 0;
  EXPECT_THROW(frame.Check(), InputError);
}

}  // namespace
}  // namespace ihs
