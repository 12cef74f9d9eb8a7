// The sequential driver: every frame of the input (or the first max_frames) through the hand
// stage and the caller's step, in order; the hand started from given joints when asked.

#include "app/sequential_scan.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "sensor/oni_writer.h"
#include "tests/frame_fixtures.h"
#include "tests/test_util.h"
#include "tools/synth/sequence.h"
#include "tracker/hand_joints_io.h"

namespace ihs::app {
namespace {

namespace fs = std::filesystem;

// Four frames of a pattern (no hand), 160 x 120, as an .oni recording.
fs::path WritePatternRecording(const test::TempDir& dir) {
  sensor::OniWriterOptions options;
  options.intrinsics = CameraIntrinsics::Carmine109().Scaled(160, 120);
  sensor::OniWriter writer(dir / "pattern.oni", options);
  for (const Frame& frame : test::MakePatternFrames(4, 160, 120)) writer.Write(frame);
  writer.Close();
  return dir / "pattern.oni";
}

std::vector<std::int64_t> FramesSeen(const fs::path& input, SequentialOptions options) {
  SequentialScan scan(input.string(), options);
  HandStage hand(ScannerOptions(), scan.intrinsics());
  std::vector<std::int64_t> seen;
  const std::int64_t frames = scan.Run(hand, [&](FramePacket& packet) {
    EXPECT_FALSE(packet.track.HasPose()) << "a pattern has no hand";
    seen.push_back(packet.frame->index);
  });
  EXPECT_EQ(frames, static_cast<std::int64_t>(seen.size()));
  return seen;
}

TEST(SequentialScanTest, EveryFrameInOrderOrTheFirstMaxFrames) {
  test::TempDir dir;
  const fs::path input = WritePatternRecording(dir);
  EXPECT_EQ(FramesSeen(input, {}), (std::vector<std::int64_t>{0, 1, 2, 3}));
  SequentialOptions first_two;
  first_two.max_frames = 2;
  EXPECT_EQ(FramesSeen(input, first_two), (std::vector<std::int64_t>{0, 1}));
}

TEST(SequentialScanTest, AnUnreadableInputIsAnInputError) {
  test::TempDir dir;
  test::WriteBytes(dir / "empty.oni", "");
  EXPECT_THROW(SequentialScan((dir / "empty.oni").string()), InputError);
}

// The first frame's hand: searched for by the tracker, or fitted from the given joints.
TEST(SequentialScanTest, TheHandStartsFromTheGivenJoints) {
  test::TempDir dir;
  synth::SequenceOptions sequence;
  sequence.last_frame = 1;
  sequence.write_tum = false;
  synth::GenerateSequence(sequence, dir.path());
  const auto truth = tracker::ReadHandJointsCsv(dir / "gt" / "hand_joints.csv");
  ASSERT_FALSE(truth.empty());
  auto first_status = [&](SequentialOptions options) {
    SequentialScan scan((dir / "sequence.oni").string(), options);
    HandStage hand(ScannerOptions(), scan.intrinsics());
    std::vector<tracker::TrackStatus> statuses;
    std::vector<double> errors;
    scan.Run(hand, [&](FramePacket& packet) {
      statuses.push_back(packet.track.status);
      if (packet.track.HasPose()) {
        errors.push_back(tracker::MeanJointError(packet.track.joints_mm,
                                                 truth.at(packet.frame->index).joints_mm));
      }
    });
    EXPECT_EQ(statuses.size(), 2u);
    return std::make_pair(statuses.at(0), errors.empty() ? 1e9 : errors.front());
  };
  EXPECT_EQ(first_status({}).first, tracker::TrackStatus::kInitialised);
  SequentialOptions from_truth;
  from_truth.first_joints_mm = truth.front().joints_mm;
  const auto [status, error_mm] = first_status(from_truth);
  EXPECT_EQ(status, tracker::TrackStatus::kTracked);
  EXPECT_LT(error_mm, 15.0);
}

}  // namespace
}  // namespace ihs::app
