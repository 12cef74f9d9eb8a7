// End-to-end tests of inhandscan-frames: info (text and JSON) and conversion, on recordings we
// write and on the real Kinect recording, including damaged and unreadable input.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sensor/oni_reader.h"
#include "sensor/oni_writer.h"
#include "sensor/tum_directory.h"
#include "tests/frame_fixtures.h"
#include "tests/test_util.h"

namespace ihs {
namespace {

test::CommandResult RunTool(const std::string& arguments) {
  return test::RunCommand(std::string(IHS_FRAMES_TOOL) + " " + arguments);
}

// Writes `frames` (160 x 120) as an .oni recording with our writer.
void WriteOni(const std::filesystem::path& path, const std::vector<Frame>& frames) {
  sensor::OniWriterOptions options;
  options.intrinsics = CameraIntrinsics::Carmine109().Scaled(160, 120);
  sensor::OniWriter writer(path, options);
  for (const Frame& frame : frames) writer.Write(frame);
  writer.Close();
}

TEST(FramesToolTest, InfoJsonDescribesOurRecordingAndConvertRoundTrips) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(4, 160, 120);
  WriteOni(dir / "a.oni", frames);
  const test::CommandResult info = RunTool("info --json " + (dir / "a.oni").string());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto json = nlohmann::json::parse(info.out);
  EXPECT_EQ(json["depth_frames"], 4);
  EXPECT_EQ(json["color_frames"], 4);
  EXPECT_EQ(json["width"], 160);
  EXPECT_EQ(json["height"], 120);
  EXPECT_NEAR(json["fx"].get<double>(), 131.25, 1e-3);
  EXPECT_EQ(json["first_timestamp_us"], frames.front().depth_timestamp_us);
  EXPECT_EQ(json["last_timestamp_us"], frames.back().depth_timestamp_us);
  EXPECT_EQ(json["recovered"], false);

  // .oni → TUM → .oni gives back the same frames.
  ASSERT_EQ(
      RunTool("-q convert " + (dir / "a.oni").string() + " " + (dir / "tum").string()).exit_code,
      0);
  ASSERT_EQ(
      RunTool("-q convert " + (dir / "tum").string() + " " + (dir / "b.oni").string()).exit_code,
      0);
  sensor::OniFileSource source(dir / "b.oni");
  source.Start();
  for (const Frame& frame : frames) {
    const sensor::SourceRead read = source.Next(std::chrono::seconds(1));
    ASSERT_EQ(read.status, sensor::SourceStatus::kFrame);
    EXPECT_EQ(read.frame->depth_mm, frame.depth_mm);
    EXPECT_EQ(read.frame->rgb, frame.rgb);
  }
}

// A conversion is written aside and moved into place whole: a failed one leaves nothing under
// the output's name (nor beside it), a folder that holds other files is not written into, and an
// existing .oni is replaced only by a complete one.
TEST(FramesToolTest, ConversionsAppearWholeOrNotAtAll) {
  test::TempDir dir;
  WriteOni(dir / "a.oni", test::MakePatternFrames(3, 160, 120));
  test::WriteBytes(dir / "junk.oni", "junk");
  test::WriteBytes(dir / "b.oni", "an older file");
  EXPECT_EQ(RunTool("-q convert " + (dir / "junk.oni").string() + " " + (dir / "b.oni").string())
                .exit_code,
            3);
  EXPECT_EQ(test::ReadFileString(dir / "b.oni"), "an older file");
  std::filesystem::create_directories(dir / "taken");
  test::WriteBytes(dir / "taken" / "notes.txt", "mine");
  const auto taken =
      RunTool("-q convert " + (dir / "a.oni").string() + " " + (dir / "taken").string());
  EXPECT_EQ(taken.exit_code, 6) << taken.err;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "taken"), {}), 1);
  ASSERT_EQ(
      RunTool("-q convert " + (dir / "a.oni").string() + " " + (dir / "b.oni").string()).exit_code,
      0);
  sensor::OniFileSource converted(dir / "b.oni");
  converted.Start();
  EXPECT_EQ(converted.FrameCount(), 3);
  // A folder whose every image is unreadable: the writer has begun, no frame comes; the partial
  // output goes.
  ASSERT_EQ(
      RunTool("-q convert " + (dir / "a.oni").string() + " " + (dir / "tum").string()).exit_code,
      0);
  for (const auto& entry : sensor::ListTumDirectory(dir / "tum", sensor::TumOptions{}))
    test::WriteBytes(dir / "tum" / entry.depth_path, "not a png");
  EXPECT_EQ(
      RunTool("-q convert " + (dir / "tum").string() + " " + (dir / "c.oni").string()).exit_code,
      3);
  // Nothing else beside the inputs and outputs: a.oni, junk.oni, b.oni, taken/, tum/.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 5);
}

TEST(FramesToolTest, DamagedRecordingConvertsWhatCanBeRecoveredAndSaysSo) {
  const std::filesystem::path kinect = test::KinectRecording();
  if (kinect.empty()) GTEST_SKIP() << "../shared/data is absent";
  test::TempDir dir;
  const std::string bytes = test::ReadFileString(kinect);
  test::WriteBytes(dir / "cut.oni", bytes.substr(0, bytes.size() * 2 / 3));
  const test::CommandResult info = RunTool("info --json " + (dir / "cut.oni").string());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto json = nlohmann::json::parse(info.out);
  EXPECT_EQ(json["recovered"], true);
  EXPECT_GE(json["depth_frames"].get<int>(), 6);
  EXPECT_LT(json["depth_frames"].get<int>(), 12);
  EXPECT_NE(info.err.find("recovered"), std::string::npos) << info.err;
  const test::CommandResult convert =
      RunTool("convert " + (dir / "cut.oni").string() + " " + (dir / "tum").string());
  EXPECT_EQ(convert.exit_code, 0) << convert.err;
  EXPECT_NE(convert.err.find("converted the"), std::string::npos) << convert.err;
}

TEST(FramesToolTest, UnreadableInputsExitNonZeroWithOneLine) {
  test::TempDir dir;
  test::WriteBytes(dir / "junk.oni", "junk");
  for (const std::string& input :
       {(dir / "junk.oni").string(), (dir / "none.oni").string(), (dir / "file.txt").string()}) {
    const test::CommandResult run = RunTool("info " + input);
    EXPECT_EQ(run.exit_code, 3) << input << ": " << run.err;
    EXPECT_NE(run.err.find("inhandscan-frames: error: "), std::string::npos) << run.err;
    EXPECT_NE(run.err.find(input), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
  EXPECT_EQ(RunTool("info --oni-reader magic x.oni").exit_code, 2);
}

}  // namespace
}  // namespace ihs
