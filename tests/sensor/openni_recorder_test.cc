#include "sensor/openni_recorder.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "sensor/oni_reader.h"
#include "sensor/usb_devices.h"
#include "tests/test_util.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

// OpenNI2's recorder works on any OpenNI2 device, including its file player: re-recording the
// real Kinect recording exercises the whole path without a camera.
TEST(OpenNiRecorderTest, RecordsARecordingThatBothReadersPlay) {
  const std::filesystem::path kinect = test::KinectRecording();
  if (kinect.empty()) GTEST_SKIP() << "../shared/data is absent";
  test::TempDir dir;
  OpenNiOptions device;
  device.uri = kinect.string();
  const std::atomic<bool> stop{false};
  const RecordingSummary summary = RecordWithOpenNi(device, dir / "again.oni", 20s, 0, stop);
  EXPECT_EQ(summary.depth_frames, 12);
  OniFileSource own(dir / "again.oni");
  own.Start();
  EXPECT_FALSE(own.Recovered());
  // OpenNI2 records every frame it delivers; the last may still be in flight when we stop.
  EXPECT_GE(own.FrameCount().value_or(0), 11);
  const SourceRead first = own.Next(1s);
  ASSERT_EQ(first.status, SourceStatus::kFrame);
  EXPECT_GT(first.frame->ValidDepthCount(), 200000);
}

TEST(OpenNiRecorderTest, LiveRecordingWhenACarmineIsConnected) {
  bool ready = false;
  const std::string usb = DescribeUsbScan(ScanPrimeSenseDevices(), &ready);
  if (!ready) GTEST_SKIP() << "no usable PrimeSense sensor: " << usb;
  test::TempDir dir;
  const std::atomic<bool> stop{false};
  const RecordingSummary summary =
      RecordWithOpenNi(OpenNiOptions{}, dir / "live.oni", 2s, 30, stop);
  EXPECT_EQ(summary.depth_frames, 30);
  OniFileSource own(dir / "live.oni");
  own.Start();
  EXPECT_GE(own.FrameCount().value_or(0), 29);
}

TEST(OpenNiRecorderTest, UnwritableOutputIsAnOutputError) {
  test::TempDir dir;
  const std::atomic<bool> stop{false};
  EXPECT_THROW(RecordWithOpenNi(OpenNiOptions{}, dir / "missing" / "x.oni", 1s, 1, stop),
               OutputError);
}

}  // namespace
}  // namespace ihs::sensor
