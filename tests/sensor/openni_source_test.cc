#include "sensor/openni_source.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "core/errors.h"
#include "sensor/open_input.h"
#include "sensor/usb_devices.h"
#include "tests/source_reading.h"
#include "tests/test_util.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

TEST(OpenNiSourceTest, PlaysTheRealKinectRecordingFrameByFrame) {
  const auto path = test::KinectRecording();
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent";
  OpenNiOptions options;
  options.uri = path.string();
  OpenNiSource source(options);
  source.Start();
  EXPECT_FALSE(source.IsLive());
  EXPECT_EQ(source.FrameCount(), 12);
  EXPECT_NEAR(source.Intrinsics().fx, 575.8, 0.5);
  EXPECT_EQ(source.Intrinsics().width, 640);
  std::vector<std::shared_ptr<const Frame>> frames;
  while (true) {
    const SourceRead read = source.Next(2s);
    if (read.status == SourceStatus::kTimeout) continue;
    if (read.status != SourceStatus::kFrame) {
      EXPECT_EQ(read.status, SourceStatus::kEndOfStream) << read.message;
      break;
    }
    frames.push_back(read.frame);
  }
  ASSERT_EQ(frames.size(), 12u);
  for (size_t i = 0; i < frames.size(); ++i) {
    const Frame& frame = *frames[i];
    EXPECT_EQ(frame.index, static_cast<std::int64_t>(i));
    ASSERT_TRUE(frame.HasColor()) << i;
    EXPECT_NO_THROW(frame.Check());
    double sum = 0;
    int valid = 0;
    for (std::uint16_t d : frame.depth_mm) {
      if (d) {
        sum += d;
        ++valid;
      }
    }
    EXPECT_GT(valid, 200000) << i;
    EXPECT_NEAR(sum / valid, 2590, 15) << i;
    EXPECT_LE(std::abs(frame.color_timestamp_us - frame.depth_timestamp_us), 34000) << i;
    if (i > 0) {
      EXPECT_NEAR(frame.depth_timestamp_us - frames[i - 1]->depth_timestamp_us, 33400, 1500);
    }
  }
  EXPECT_EQ(source.FramesWithoutColor(), 0);
}

// At the recorded pace OpenNI2's player still delivers a frame only when one is asked for (its
// own pacing delivered on its own clock, and stopping its streams meanwhile crashed under load):
// every frame comes, on time, and a replay stopped at any frame stops cleanly.
TEST(OpenNiSourceTest, AtTheRecordedPaceEveryFrameComesOnTimeAndAStopAnywhereIsClean) {
  const auto path = test::KinectRecording();
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent";
  InputOptions options;
  options.pacing = Pacing::kRealTime;
  options.oni_backend = OniBackend::kOpenNi;
  for (const int stop_after : {0, 1, 5}) {
    auto source = OpenInput(path.string(), options);
    source->Start();
    EXPECT_TRUE(source->IsLive());
    for (int i = 0; i < stop_after; ++i) ASSERT_EQ(source->Next(2s).status, SourceStatus::kFrame);
    source->Stop();
  }
  auto source = OpenInput(path.string(), options);
  source->Start();
  const auto start = std::chrono::steady_clock::now();
  int frames = 0;
  while (true) {
    const SourceRead read = source->Next(2s);
    if (read.status == SourceStatus::kTimeout) continue;
    if (read.status != SourceStatus::kFrame) {
      EXPECT_EQ(read.status, SourceStatus::kEndOfStream) << read.message;
      break;
    }
    EXPECT_EQ(read.frame->index, frames);
    ++frames;
  }
  EXPECT_EQ(frames, 12);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 11 * 33ms);  // 11 gaps of 33.4 ms.
  EXPECT_EQ(source->MissedFrames(), 0);
  source->Stop();
}

TEST(OpenNiSourceTest, MissingAndTruncatedFilesAreInputErrors) {
  test::TempDir dir;
  OpenNiOptions options;
  options.uri = (dir / "missing.oni").string();
  EXPECT_THROW(OpenNiSource(options).Start(), InputError);
  const auto path = test::KinectRecording();
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent";
  const std::string bytes = test::ReadFileString(path);
  for (const double fraction : {0.1, 0.5, 0.9, 0.999}) {
    test::WriteBytes(dir / "cut.oni",
                     bytes.substr(0, static_cast<size_t>(bytes.size() * fraction)));
    options.uri = (dir / "cut.oni").string();
    try {
      OpenNiSource(options).Start();
      FAIL() << "OpenNI2 played a file cut at " << fraction;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("cut.oni: OpenNI2 cannot play it"),
                std::string::npos)
          << error.what();
    }
  }
}

TEST(OpenNiSourceTest, LiveDeviceStreamsWhenACarmineIsConnected) {
  bool ready = false;
  const std::string usb = DescribeUsbScan(ScanPrimeSenseDevices(), &ready);
  if (!ready) GTEST_SKIP() << "no usable PrimeSense sensor: " << usb;
  OpenNiSource source(OpenNiOptions{});
  source.Start();
  EXPECT_TRUE(source.IsLive());
  int frames = 0;
  for (int attempt = 0; attempt < 100 && frames < 10; ++attempt) {
    const SourceRead read = source.Next(1s);
    ASSERT_NE(read.status, SourceStatus::kDisconnected) << read.message;
    if (read.status == SourceStatus::kFrame) {
      EXPECT_EQ(read.frame->width, 640);
      EXPECT_GT(read.frame->ValidDepthCount(), 1000);
      ++frames;
    }
  }
  EXPECT_EQ(frames, 10);
}

TEST(OpenNiSourceTest, AbsentLiveDeviceIsADeviceErrorThatSaysWhy) {
  bool ready = false;
  DescribeUsbScan(ScanPrimeSenseDevices(), &ready);
  if (ready) GTEST_SKIP() << "a sensor is connected";
  OpenNiOptions options;
  options.uri = "no-such-device-uri";
  try {
    OpenNiSource(options).Start();
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& error) {
    const std::string text = error.what();
    EXPECT_NE(text.find("cannot open the depth camera"), std::string::npos) << text;
    EXPECT_TRUE(text.find("PrimeSense") != std::string::npos ||
                text.find("USB is not available") != std::string::npos)
        << text;
  }
}

}  // namespace
}  // namespace ihs::sensor
