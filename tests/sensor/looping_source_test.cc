// A recording played over and over reads as one long recording: frames numbered on, timestamps
// going on at the frame rate, the same images round after round.

#include "sensor/looping_source.h"

#include <gtest/gtest.h>

#include "sensor/replay_source.h"
#include "tests/frame_fixtures.h"
#include "tests/source_reading.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

TEST(LoopingSourceTest, ThreeRoundsReadAsOneRecording) {
  const std::vector<Frame> frames = test::MakePatternFrames(3, 64, 48);
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109().Scaled(64, 48);
  LoopingSource source(std::make_unique<ReplaySource>(frames, intrinsics), 3);
  ASSERT_EQ(source.FrameCount(), 9);
  const auto read = test::ReadAllFrames(source);
  ASSERT_EQ(read.size(), 9u);
  const std::int64_t interval = frames[1].depth_timestamp_us - frames[0].depth_timestamp_us;
  ASSERT_GT(interval, 0);
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i]->index, static_cast<std::int64_t>(i));
    EXPECT_EQ(read[i]->depth_mm, frames[i % 3].depth_mm) << "frame " << i;
    EXPECT_EQ(read[i]->rgb, frames[i % 3].rgb) << "frame " << i;
    EXPECT_EQ(read[i]->depth_timestamp_us, frames[0].depth_timestamp_us + interval * i)
        << "frame " << i;
  }
}

TEST(LoopingSourceTest, AnEmptyRecordingEndsAtOnceAndZeroRoundsAreRefused) {
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  LoopingSource empty(std::make_unique<ReplaySource>(std::vector<Frame>{}, intrinsics), 5);
  EXPECT_TRUE(test::ReadAllFrames(empty).empty());
  EXPECT_THROW(LoopingSource(std::make_unique<ReplaySource>(std::vector<Frame>{}, intrinsics), 0),
               std::invalid_argument);
}

}  // namespace
}  // namespace ihs::sensor
