#include "sensor/paced_source.h"

#include <gtest/gtest.h>

#include <chrono>

#include "sensor/replay_source.h"
#include "tests/frame_fixtures.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

TEST(PacedSourceTest, DeliversFramesAtTheirRecordedRate) {
  // Frames 33.3 ms apart: frame 6 is due 200 ms after frame 0.
  PacedSource source(
      std::make_unique<ReplaySource>(test::MakePatternFrames(7, 16, 12), CameraIntrinsics{}));
  source.Start();
  EXPECT_TRUE(source.IsLive());
  const auto start = std::chrono::steady_clock::now();
  int frames = 0;
  while (frames < 7) {
    const SourceRead read = source.Next(1s);
    ASSERT_EQ(read.status, SourceStatus::kFrame);
    ++frames;
  }
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_GE(elapsed, 195ms);
  EXPECT_EQ(source.Next(1s).status, SourceStatus::kEndOfStream);
}

TEST(PacedSourceTest, TimesOutWhenTheNextFrameIsNotDueAndKeepsIt) {
  PacedSource source(
      std::make_unique<ReplaySource>(test::MakePatternFrames(2, 16, 12), CameraIntrinsics{}),
      0.5);  // Half speed: frame 1 is due after 66.7 ms.
  source.Start();
  ASSERT_EQ(source.Next(1s).status, SourceStatus::kFrame);
  EXPECT_EQ(source.Next(10ms).status, SourceStatus::kTimeout);
  const SourceRead read = source.Next(1s);
  ASSERT_EQ(read.status, SourceStatus::kFrame);
  EXPECT_EQ(read.frame->index, 1);
}

TEST(PacedSourceTest, WithPacingWrapsOnlyForRealTime) {
  auto fast = WithPacing(
      std::make_unique<ReplaySource>(test::MakePatternFrames(1, 4, 4), CameraIntrinsics{}),
      Pacing::kAsFastAsPossible);
  EXPECT_FALSE(fast->IsLive());
  auto paced = WithPacing(std::move(fast), Pacing::kRealTime);
  EXPECT_TRUE(paced->IsLive());
  EXPECT_THROW(PacedSource(nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::sensor
