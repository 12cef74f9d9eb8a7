#include "sensor/replay_source.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/errors.h"
#include "tests/frame_fixtures.h"
#include "tests/source_reading.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

TEST(ReplaySourceTest, ServesFramesInOrderThenEndOfStream) {
  ReplaySource source(test::MakePatternFrames(5, 32, 24), CameraIntrinsics{});
  source.Start();
  EXPECT_EQ(source.FrameCount(), 5);
  EXPECT_FALSE(source.IsLive());
  SourceStatus end;
  const auto frames = test::ReadAllFrames(source, &end);
  EXPECT_EQ(end, SourceStatus::kEndOfStream);
  ASSERT_EQ(frames.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(frames[i]->index, i);
  EXPECT_EQ(source.Next(0ms).status, SourceStatus::kEndOfStream);  // Stays ended.
}

TEST(ReplaySourceTest, InjectsDropsDuplicatesAndCorruptFrames) {
  FaultPlan faults;
  faults.drop = {1, 3};
  faults.duplicate_timestamp = {4};
  faults.wrong_size = {5};
  faults.all_zero = {6};
  ReplaySource source(test::MakePatternFrames(8, 32, 24), CameraIntrinsics{}, faults);
  source.Start();
  SourceStatus end;
  const auto frames = test::ReadAllFrames(source, &end);
  ASSERT_EQ(frames.size(), 6u);
  std::vector<std::int64_t> indices;
  for (const auto& frame : frames) indices.push_back(frame->index);
  EXPECT_EQ(indices, (std::vector<std::int64_t>{0, 2, 4, 5, 6, 7}));
  EXPECT_EQ(source.MissedFrames(), 2);  // The dropped ones, as a sensor would report them.
  EXPECT_EQ(frames[2]->depth_timestamp_us, test::MakePatternFrame(3).depth_timestamp_us);
  EXPECT_THROW(frames[3]->Check(), InputError);
  EXPECT_EQ(frames[4]->ValidDepthCount(), 0);
  EXPECT_GT(frames[5]->ValidDepthCount(), 600);
}

TEST(ReplaySourceTest, DisconnectsAfterNFramesAndKeepsDeliveredFramesValid) {
  FaultPlan faults;
  faults.disconnect_after = 3;
  ReplaySource source(test::MakePatternFrames(10, 32, 24), CameraIntrinsics{}, faults, true);
  source.Start();
  EXPECT_TRUE(source.IsLive());
  SourceStatus end;
  const auto frames = test::ReadAllFrames(source, &end);
  EXPECT_EQ(end, SourceStatus::kDisconnected);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2]->DepthAt(5, 5), test::MakePatternFrame(2, 32, 24).DepthAt(5, 5));
}

TEST(ReplaySourceTest, StallTimesOutThenDeliversTheFrame) {
  FaultPlan faults;
  faults.stall_ms = {{1, 120}};
  ReplaySource source(test::MakePatternFrames(3, 32, 24), CameraIntrinsics{}, faults);
  source.Start();
  ASSERT_EQ(source.Next(0ms).status, SourceStatus::kFrame);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(source.Next(30ms).status, SourceStatus::kTimeout);
  const SourceRead late = source.Next(1s);
  ASSERT_EQ(late.status, SourceStatus::kFrame);
  EXPECT_EQ(late.frame->index, 1);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 115ms);
}

TEST(ReplaySourceTest, AHeldFrameComesOnlyOnceItsGateOpens) {
  FaultPlan faults;
  const auto gate = std::make_shared<FrameGate>();
  faults.held[1] = gate;
  ReplaySource source(test::MakePatternFrames(3, 32, 24), CameraIntrinsics{}, faults);
  source.Start();
  ASSERT_EQ(source.Next(0ms).status, SourceStatus::kFrame);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(source.Next(10ms).status, SourceStatus::kTimeout);
  std::thread opener([&] { gate->Open(); });
  const SourceRead held = source.Next(60s);  // Returns as soon as the gate opens.
  opener.join();
  ASSERT_EQ(held.status, SourceStatus::kFrame);
  EXPECT_EQ(held.frame->index, 1);
  EXPECT_EQ(source.Next(0ms).frame->index, 2);
}

TEST(ReplaySourceTest, WrapsAnotherSourceAndCountsItsFrames) {
  auto inner =
      std::make_unique<ReplaySource>(test::MakePatternFrames(4, 16, 12), CameraIntrinsics{});
  FaultPlan faults;
  faults.drop = {0};
  ReplaySource source(std::move(inner), faults);
  source.Start();
  SourceStatus end;
  const auto frames = test::ReadAllFrames(source, &end);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames.front()->index, 1);
  EXPECT_NE(source.Description().find("replay shim over replay shim"), std::string::npos);
}

}  // namespace
}  // namespace ihs::sensor
