// Whether a frame hides the object: against the most points of the recent frames in view.

#include "fusion/hidden_span.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace ihs::fusion {
namespace {

TEST(HiddenSpanTest, AFrameWithFewPointsAgainstTheRecentFramesInViewHidesTheObject) {
  HiddenOptions options;
  options.share = 0.4;
  options.reference_frames = 3;
  HiddenSpan span(options);
  EXPECT_FALSE(span.Observe(150));  // Nothing to compare the first frame with.
  EXPECT_FALSE(span.Observe(3000));
  EXPECT_FALSE(span.Observe(1300));  // A box turned edge-on: 43 % of its largest view.
  EXPECT_TRUE(span.Observe(1100));
  EXPECT_TRUE(span.Observe(250));
  EXPECT_EQ(span.hidden_frames(), 2);
  // Hidden frames do not lower the reference: still 3000.
  EXPECT_TRUE(span.Observe(1190));
  EXPECT_FALSE(span.Observe(1250));
  EXPECT_EQ(span.hidden_frames(), 0);
  // Once 3000 has left the last three frames in view, 1300 is the reference.
  EXPECT_FALSE(span.Observe(1300));
  EXPECT_FALSE(span.Observe(1000));
  EXPECT_FALSE(span.Observe(600));
  EXPECT_TRUE(span.Observe(480));
}

TEST(HiddenSpanTest, ShareZeroNeverHidesAndBadOptionsAreRefused) {
  HiddenOptions off;
  off.share = 0;
  HiddenSpan span(off);
  for (int points : {3000, 10, 0, 3000}) EXPECT_FALSE(span.Observe(points));
  HiddenOptions bad;
  bad.share = 1.0;
  EXPECT_THROW(HiddenSpan{bad}, std::invalid_argument);
  bad = {};
  bad.reference_frames = 0;
  EXPECT_THROW(HiddenSpan{bad}, std::invalid_argument);
  bad = {};
  bad.shown_share = 1.5;
  EXPECT_THROW(HiddenSpan{bad}, std::invalid_argument);
  bad = {};
  bad.background_margin_mm = -1;
  EXPECT_THROW(HiddenSpan{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion
