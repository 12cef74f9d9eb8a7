#include "sensor/tum_directory.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>

#include "core/errors.h"
#include "tests/frame_fixtures.h"
#include "tests/source_reading.h"
#include "tests/test_util.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

void WriteFrames(const std::filesystem::path& folder, const std::vector<Frame>& frames,
                 const CameraIntrinsics& intrinsics) {
  TumWriter writer(folder, intrinsics);
  for (const Frame& frame : frames) writer.Write(frame);
  writer.Finish();
}

// Every frame of `source`, and what reading them printed on stderr.
std::vector<std::shared_ptr<const Frame>> ReadPrinting(TumDirectorySource& source,
                                                       std::string* printed) {
  testing::internal::CaptureStderr();
  auto frames = test::ReadAllFrames(source);
  *printed = testing::internal::GetCapturedStderr();
  return frames;
}

TEST(TumDirectoryTest, RoundTripsDepthColourTimestampsAndIntrinsicsExactly) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(4, 64, 48);
  CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109().Scaled(64, 48);
  intrinsics.fx = 52.123456789;
  WriteFrames(dir.path(), frames, intrinsics);

  TumDirectorySource source(dir.path());
  const auto read = test::ReadAllFrames(source);
  ASSERT_EQ(read.size(), frames.size());
  EXPECT_EQ(source.FrameCount(), 4);
  EXPECT_DOUBLE_EQ(source.Intrinsics().fx, 52.123456789);
  EXPECT_EQ(source.Intrinsics().width, 64);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(read[i]->depth_mm, frames[i].depth_mm) << i;
    EXPECT_EQ(read[i]->rgb, frames[i].rgb) << i;
    EXPECT_EQ(read[i]->depth_timestamp_us, frames[i].depth_timestamp_us);
    EXPECT_EQ(read[i]->color_timestamp_us, frames[i].color_timestamp_us);
    EXPECT_EQ(read[i]->index, static_cast<std::int64_t>(i));
  }
}

TEST(TumDirectoryTest, DepthScaleIsAppliedBothWays) {
  test::TempDir dir;
  TumOptions options;
  options.depth_scale_per_m = 1000;  // 1 unit = 1 mm.
  Frame frame = test::MakePatternFrame(0, 16, 12);
  {
    TumWriter writer(dir.path(), CameraIntrinsics{}.Scaled(16, 12), options);
    writer.Write(frame);
  }
  TumDirectorySource as_millimetres(dir.path(), options);
  EXPECT_EQ(test::ReadAllFrames(as_millimetres).at(0)->depth_mm, frame.depth_mm);
  TumDirectorySource as_tum(dir.path());  // Read as 5000 per metre: 1 unit = 0.2 mm.
  const auto scaled = test::ReadAllFrames(as_tum).at(0);
  EXPECT_EQ(scaled->DepthAt(1, 1),
            static_cast<std::uint16_t>(std::lround(frame.DepthAt(1, 1) / 5.0)));
}

TEST(TumDirectoryTest, MatchesByNearestTimestampWithoutAssociations) {
  test::TempDir dir;
  auto frames = test::MakePatternFrames(5, 16, 12);
  frames[2].color_timestamp_us = frames[2].depth_timestamp_us + 40'000;  // Beyond 20 ms.
  WriteFrames(dir.path(), frames, CameraIntrinsics{}.Scaled(16, 12));
  std::filesystem::remove(dir / "associations.txt");

  int unmatched = -1;
  const auto entries = ListTumDirectory(dir.path(), TumOptions{}, &unmatched);
  // Depth 2's colour (at +40 ms) is 6.7 ms from depth 3, but depth 3's own colour is closer.
  EXPECT_EQ(unmatched, 1);
  ASSERT_EQ(entries.size(), 4u);
  for (const TumEntry& entry : entries) {
    EXPECT_LT(std::abs(entry.color_time_s - entry.depth_time_s), 0.0015);
  }
  TumDirectorySource source(dir.path());
  EXPECT_EQ(test::ReadAllFrames(source).size(), 4u);
  EXPECT_EQ(source.UnmatchedDepth(), 1);
}

TEST(TumDirectoryTest, UnreadableImagesAreSkippedAndCounted) {
  test::TempDir dir;
  WriteFrames(dir.path(), test::MakePatternFrames(4, 16, 12), CameraIntrinsics{}.Scaled(16, 12));
  const auto entries = ListTumDirectory(dir.path(), TumOptions{});
  test::WriteBytes(dir / entries[1].depth_path, "not a png");
  test::WriteBytes(dir / entries[2].color_path, "");  // An empty file (imdecode throws on none).
  TumDirectorySource source(dir.path());
  const auto frames = test::ReadAllFrames(source);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(source.SkippedFrames(), 2);
  EXPECT_EQ(frames[1]->index, 1);  // Indices count delivered frames.
}

// Damaged PNGs are decoded by libpng directly: the frame is skipped with the scanner's one-line
// warning naming libpng's reason, and libpng prints nothing of its own (through OpenCV it printed
// "libpng error: IDAT: incorrect data check" lines beside it).
TEST(TumDirectoryTest, DamagedPngsAreSkippedWithOneLineAndLibpngSaysNothing) {
  test::TempDir dir;
  WriteFrames(dir.path(), test::MakePatternFrames(4, 64, 48), CameraIntrinsics{}.Scaled(64, 48));
  const auto entries = ListTumDirectory(dir.path(), TumOptions{});
  std::string depth = test::ReadFileString(dir / entries[1].depth_path);
  depth[depth.find("IDAT") + 40] ^= 0x5A;  // Compressed data that no longer checks.
  test::WriteBytes(dir / entries[1].depth_path, depth);
  const std::string colour = test::ReadFileString(dir / entries[2].color_path);
  test::WriteBytes(dir / entries[2].color_path, colour.substr(0, colour.size() / 2));
  TumDirectorySource source(dir.path());
  std::string printed;
  const auto frames = ReadPrinting(source, &printed);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(source.SkippedFrames(), 2);
  EXPECT_EQ(printed.find("libpng"), std::string::npos) << printed;
}

// JPEG colour images (TUM's own recordings, Open3D's) are decoded by libjpeg directly: good ones
// read as OpenCV reads them, a damaged one skips its frame with the scanner's one-line warning,
// and libjpeg prints nothing of its own (through OpenCV it printed "Premature end of JPEG file"
// and "Corrupt JPEG data" lines, and returned the damaged images as frames).
TEST(TumDirectoryTest, DamagedJpegsAreSkippedWithOneLineAndLibjpegSaysNothing) {
  test::TempDir dir;
  WriteFrames(dir.path(), test::MakePatternFrames(4, 64, 48), CameraIntrinsics{}.Scaled(64, 48));
  const std::regex png_colour("(rgb/[0-9.]+)\\.png");
  for (const char* list : {"rgb.txt", "associations.txt"}) {
    test::WriteBytes(dir / list,
                     std::regex_replace(test::ReadFileString(dir / list), png_colour, "$1.jpg"));
  }
  const auto entries = ListTumDirectory(dir.path(), TumOptions{});
  ASSERT_EQ(entries.size(), 4u);
  std::vector<cv::Mat> expected;
  for (const TumEntry& entry : entries) {
    const std::filesystem::path png =
        dir / std::regex_replace(entry.color_path, std::regex("\\.jpg$"), ".png");
    std::vector<std::uint8_t> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", cv::imread(png.string(), cv::IMREAD_COLOR), jpeg));
    test::WriteBytes(dir / entry.color_path, std::string(jpeg.begin(), jpeg.end()));
    cv::Mat rgb;
    cv::cvtColor(cv::imdecode(jpeg, cv::IMREAD_COLOR), rgb, cv::COLOR_BGR2RGB);
    expected.push_back(rgb);
  }
  const std::string jpeg = test::ReadFileString(dir / entries[1].color_path);
  test::WriteBytes(dir / entries[1].color_path, jpeg.substr(0, jpeg.size() * 3 / 4));
  TumDirectorySource source(dir.path());
  std::string printed;
  const auto frames = ReadPrinting(source, &printed);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(source.SkippedFrames(), 1);
  for (size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat& rgb = expected[i == 0 ? 0 : i + 1];
    EXPECT_EQ(frames[i]->rgb, std::vector<std::uint8_t>(rgb.data, rgb.data + rgb.total() * 3)) << i;
  }
  std::istringstream lines(printed);  // Only the scanner's own warnings, if any go to stderr.
  for (std::string line; std::getline(lines, line);) {
    EXPECT_NE(line.find("skipping a frame"), std::string::npos) << line;
  }
}

// Colour images in PNG's other forms (grey, colour with alpha) read as the same colours.
TEST(TumDirectoryTest, ColourPngsOfEveryKindReadAsTheirColours) {
  test::TempDir dir;
  auto frames = test::MakePatternFrames(1, 16, 12);
  for (size_t p = 0; p < frames[0].rgb.size(); p += 3) {
    frames[0].rgb[p + 1] = frames[0].rgb[p + 2] = frames[0].rgb[p];  // Grey.
  }
  WriteFrames(dir.path(), frames, CameraIntrinsics{}.Scaled(16, 12));
  const auto entries = ListTumDirectory(dir.path(), TumOptions{});
  cv::Mat grey(12, 16, CV_8UC1), with_alpha(12, 16, CV_8UC4);
  for (int i = 0; i < 16 * 12; ++i) {
    grey.data[i] = frames[0].rgb[3 * i];
    for (int c = 0; c < 3; ++c) with_alpha.data[4 * i + c] = frames[0].rgb[3 * i];
    with_alpha.data[4 * i + 3] = 255;
  }
  for (const cv::Mat& image : {grey, with_alpha}) {
    std::vector<std::uint8_t> png;
    ASSERT_TRUE(cv::imencode(".png", image, png));
    test::WriteBytes(dir / entries[0].color_path, std::string(png.begin(), png.end()));
    TumDirectorySource source(dir.path());
    const auto read = test::ReadAllFrames(source);
    ASSERT_EQ(read.size(), 1u);
    EXPECT_EQ(read[0]->rgb, frames[0].rgb) << image.channels() << " channels";
    EXPECT_EQ(read[0]->depth_mm, frames[0].depth_mm);
  }
}

TEST(TumDirectoryTest, ImagesThatAreNotFilesOrDeclareHugeSizesAreSkippedUndecoded) {
  test::TempDir dir;
  WriteFrames(dir.path(), test::MakePatternFrames(4, 16, 12), CameraIntrinsics{}.Scaled(16, 12));
  const auto entries = ListTumDirectory(dir.path(), TumOptions{});
  // A FIFO in place of a depth image would block a reader for ever.
  std::filesystem::remove(dir / entries[1].depth_path);
  ASSERT_EQ(mkfifo((dir / entries[1].depth_path).c_str(), 0600), 0);
  // A valid PNG whose header says 20000 x 20000 pixels (1.2 GB decoded): patched IHDR.
  std::string png = test::ReadFileString(dir / entries[2].depth_path);
  ASSERT_EQ(png.substr(12, 4), "IHDR");
  const char huge[8] = {0, 0, 0x4e, 0x20, 0, 0, 0x4e, 0x20};
  png.replace(16, 8, huge, 8);
  test::WriteBytes(dir / entries[2].color_path, png);
  TumDirectorySource source(dir.path());
  const auto frames = test::ReadAllFrames(source);
  EXPECT_EQ(frames.size(), 2u);
  EXPECT_EQ(source.SkippedFrames(), 2);
}

TEST(TumDirectoryTest, BadFoldersAndListsAreInputErrors) {
  test::TempDir dir;
  EXPECT_THROW(TumDirectorySource(dir / "missing").Start(), InputError);
  EXPECT_THROW(TumDirectorySource(dir.path()).Start(), InputError);  // No lists.
  test::WriteBytes(dir / "depth.txt", "# header\n1.0 depth/a.png\n");
  test::WriteBytes(dir / "rgb.txt", "1.0\n");
  try {
    TumDirectorySource(dir.path()).Start();
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("rgb.txt: line 1"), std::string::npos) << error.what();
  }
  test::WriteBytes(dir / "rgb.txt", "5.0 rgb/a.png\n");  // Nothing within 20 ms.
  EXPECT_THROW(TumDirectorySource(dir.path()).Start(), InputError);
  // A timestamp whose microseconds overflow 64 bits (it became INT64_MIN in trajectory.txt).
  test::WriteBytes(dir / "depth.txt", "1e13 depth/a.png\n");
  test::WriteBytes(dir / "rgb.txt", "1e13 rgb/a.png\n");
  EXPECT_THROW(TumDirectorySource(dir.path()).Start(), InputError);
  test::WriteBytes(dir / "associations.txt", "1.0 rgb/a.png 1e13 depth/a.png\n");
  EXPECT_THROW(TumDirectorySource(dir.path()).Start(), InputError);
}

TEST(TumDirectoryTest, ParsesIntrinsicsFromTheCommandLine) {
  const CameraIntrinsics k = ParseIntrinsics("570.3,570.3,320,240");
  EXPECT_DOUBLE_EQ(k.fx, 570.3);
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(ParseIntrinsics("100,101,50,40,100,80").height, 80);
  EXPECT_THROW(ParseIntrinsics("570,570,320"), std::invalid_argument);
  EXPECT_THROW(ParseIntrinsics("570,abc,320,240"), std::invalid_argument);
  EXPECT_THROW(ParseIntrinsics("-570,570,320,240"), std::invalid_argument);
}

TEST(TumDirectoryTest, ReadsIntrinsicsFilesInBothForms) {
  test::TempDir dir;
  test::WriteBytes(dir / "plain.txt", "570.5 571 320 240 640 480\n");
  EXPECT_DOUBLE_EQ(ReadIntrinsicsFile(dir / "plain.txt").fy, 571);
  // Open3D's PinholeCameraIntrinsic JSON: the matrix in column-major order.
  test::WriteBytes(dir / "open3d.json",
                   R"({"width": 848, "height": 480, "intrinsic_matrix": )"
                   R"([421.5, 0.0, 0.0, 0.0, 420.25, 0.0, 424.0, 238.5, 1.0]})");
  const CameraIntrinsics k = ReadIntrinsicsFile(dir / "open3d.json");
  EXPECT_EQ(k.width, 848);
  EXPECT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.fx, 421.5);
  EXPECT_DOUBLE_EQ(k.fy, 420.25);
  EXPECT_DOUBLE_EQ(k.cx, 424.0);
  EXPECT_DOUBLE_EQ(k.cy, 238.5);
  // What a scan writes (camera_intrinsic.json) reads back the same.
  test::WriteBytes(dir / "written.json", Open3dIntrinsicsJson(k));
  const CameraIntrinsics back = ReadIntrinsicsFile(dir / "written.json");
  EXPECT_EQ(back.width, k.width);
  EXPECT_EQ(back.height, k.height);
  EXPECT_DOUBLE_EQ(back.fx, k.fx);
  EXPECT_DOUBLE_EQ(back.fy, k.fy);
  EXPECT_DOUBLE_EQ(back.cx, k.cx);
  EXPECT_DOUBLE_EQ(back.cy, k.cy);
  for (const char* bad : {R"({"width": 640})",
                          R"({"width": 640, "height": 480, )"
                          R"("intrinsic_matrix": [1, 2, 3]})",
                          "{not json", "570 570 320"}) {
    test::WriteBytes(dir / "bad", bad);
    EXPECT_THROW(ReadIntrinsicsFile(dir / "bad"), InputError) << bad;
  }
}

// The folders Open3D's recorders write: depth/ and color/ paired by name, depth in mm, the
// intrinsics in camera_intrinsic.json.
TEST(TumDirectoryTest, ReadsOpen3dsLayout) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(3, 32, 24);
  std::filesystem::create_directories(dir / "depth");
  std::filesystem::create_directories(dir / "color");
  for (size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu", i);
    const Frame& f = frames[i];
    cv::Mat depth(f.height, f.width, CV_16UC1, const_cast<std::uint16_t*>(f.depth_mm.data()));
    cv::Mat rgb(f.height, f.width, CV_8UC3, const_cast<std::uint8_t*>(f.rgb.data())), bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    ASSERT_TRUE(cv::imwrite((dir / "depth" / (std::string(name) + ".png")).string(), depth));
    ASSERT_TRUE(cv::imwrite((dir / "color" / (std::string(name) + ".png")).string(), bgr));
  }
  EXPECT_TRUE(IsOpen3dFolder(dir.path()));
  test::WriteBytes(dir / "camera_intrinsic.json",
                   R"({"width": 32, "height": 24, "intrinsic_matrix": )"
                   R"([26.0, 0, 0, 0, 26.5, 0, 15.5, 11.5, 1]})");
  TumDirectorySource source(dir.path());
  const auto read = test::ReadAllFrames(source);
  ASSERT_EQ(read.size(), frames.size());
  EXPECT_DOUBLE_EQ(source.Intrinsics().fy, 26.5);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(read[i]->depth_mm, frames[i].depth_mm) << i;  // Millimetres, unscaled.
    EXPECT_EQ(read[i]->rgb, frames[i].rgb) << i;
    EXPECT_EQ(read[i]->index, static_cast<std::int64_t>(i));
  }
  // Without its intrinsics file, the default camera's, scaled to the images (with a warning).
  std::filesystem::remove(dir / "camera_intrinsic.json");
  TumDirectorySource defaults(dir.path());
  defaults.Start();
  EXPECT_EQ(defaults.Intrinsics().width, 32);
}

}  // namespace
}  // namespace ihs::sensor
