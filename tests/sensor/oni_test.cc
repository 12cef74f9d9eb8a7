// The project's .oni writer and reader, checked against OpenNI2's own player and the real
// Kinect v1 recording in ../shared/data.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "core/errors.h"
#include "sensor/oni_reader.h"
#include "sensor/oni_writer.h"
#include "sensor/open_input.h"
#include "sensor/openni_source.h"
#include "tests/frame_fixtures.h"
#include "tests/source_reading.h"
#include "tests/test_util.h"

namespace ihs::sensor {
namespace {

using namespace std::chrono_literals;

std::vector<std::shared_ptr<const Frame>> ReadWithOpenNi(const std::filesystem::path& path,
                                                         SourceStatus* end = nullptr) {
  OpenNiOptions options;
  options.uri = path.string();
  OpenNiSource source(options);
  return test::ReadAllFrames(source, end);
}

std::vector<std::shared_ptr<const Frame>> ReadWithOwnReader(const std::filesystem::path& path) {
  OniFileSource source(path);
  return test::ReadAllFrames(source);
}

void WriteOni(const std::filesystem::path& path, const std::vector<Frame>& frames,
              OniDepthCodec codec, int width = 640, int height = 480) {
  OniWriterOptions options;
  options.intrinsics = CameraIntrinsics::Carmine109().Scaled(width, height);
  options.depth_codec = codec;
  OniWriter writer(path, options);
  for (const Frame& frame : frames) writer.Write(frame);
  writer.Close();
}

void ExpectSameFrames(const std::vector<std::shared_ptr<const Frame>>& read,
                      const std::vector<Frame>& written) {
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < written.size(); ++i) {
    EXPECT_EQ(read[i]->depth_mm, written[i].depth_mm) << "frame " << i;
    EXPECT_EQ(read[i]->rgb, written[i].rgb) << "frame " << i;
    EXPECT_EQ(read[i]->depth_timestamp_us, written[i].depth_timestamp_us) << "frame " << i;
    EXPECT_EQ(read[i]->color_timestamp_us, written[i].color_timestamp_us) << "frame " << i;
  }
}

class OniWriterTest : public testing::TestWithParam<OniDepthCodec> {};

TEST_P(OniWriterTest, OpenNi2PlaysOurFilesBackExactly) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(6);
  WriteOni(dir / "ours.oni", frames, GetParam());
  ExpectSameFrames(ReadWithOpenNi(dir / "ours.oni"), frames);
  OpenNiOptions options;
  options.uri = (dir / "ours.oni").string();
  OpenNiSource source(options);
  source.Start();
  EXPECT_EQ(source.FrameCount(), 6);
  EXPECT_NEAR(source.Intrinsics().fx, 525.0, 1e-3);
  EXPECT_NEAR(source.Intrinsics().fy, 525.0, 1e-3);
}

TEST_P(OniWriterTest, OwnReaderReadsOurFilesBackExactly) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(6, 160, 120);
  WriteOni(dir / "ours.oni", frames, GetParam(), 160, 120);
  ExpectSameFrames(ReadWithOwnReader(dir / "ours.oni"), frames);
  OniFileSource source(dir / "ours.oni");
  source.Start();
  EXPECT_FALSE(source.Recovered());
  EXPECT_EQ(source.index().version, "1.0.1.0");
  EXPECT_EQ(source.index().FirstOfType(OniNodeType::kDepth)->declared_frames, 6u);
  EXPECT_NEAR(source.Intrinsics().fx, 525.0 / 4, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Codecs, OniWriterTest,
                         testing::Values(OniDepthCodec::k16zTable, OniDepthCodec::kUncompressed));

TEST(OniWriterTest, RejectsFramesOfAnotherSizeAndUnwritablePaths) {
  test::TempDir dir;
  OniWriterOptions options;
  OniWriter writer(dir / "a.oni", options);
  EXPECT_THROW(writer.Write(test::MakePatternFrame(0, 32, 24)), std::invalid_argument);
  EXPECT_THROW(OniWriter(dir / "missing" / "a.oni", options), OutputError);
}

TEST(OniReaderTest, AgreesWithOpenNi2BitForBitOnTheRealKinectRecording) {
  const auto path = test::KinectRecording();
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent";
  const auto ours = ReadWithOwnReader(path);
  const auto theirs = ReadWithOpenNi(path);
  ASSERT_EQ(ours.size(), 12u);
  ASSERT_EQ(theirs.size(), 12u);
  for (size_t i = 0; i < ours.size(); ++i) {
    EXPECT_EQ(ours[i]->depth_mm, theirs[i]->depth_mm) << "depth of frame " << i;
    EXPECT_EQ(ours[i]->depth_timestamp_us, theirs[i]->depth_timestamp_us);
    EXPECT_EQ(ours[i]->color_timestamp_us, theirs[i]->color_timestamp_us);
    ASSERT_EQ(ours[i]->rgb.size(), theirs[i]->rgb.size());
    // Both decode the same JPEG; libjpeg builds may round a few values differently.
    double difference = 0;
    for (size_t k = 0; k < ours[i]->rgb.size(); ++k) {
      difference += std::abs(int(ours[i]->rgb[k]) - int(theirs[i]->rgb[k]));
    }
    EXPECT_LT(difference / ours[i]->rgb.size(), 1.0) << "colour of frame " << i;
    EXPECT_NEAR(ours[i]->ValidDepthCount(), 235000, 10000);
  }
}

// A colour frame whose JPEG libjpeg finds damaged (here an end marker inside its data) plays
// without colour, and libjpeg prints nothing (through OpenCV it printed "Corrupt JPEG data:
// premature end of data segment" and gave a damaged image).
TEST(OniReaderTest, ADamagedJpegColourFramePlaysWithoutColourAndSilently) {
  const auto path = test::KinectRecording();
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent";
  std::string bytes = test::ReadFileString(path);
  const OniIndex index = IndexOni(bytes, "real");
  const OniNode& color = *index.FirstOfType(OniNodeType::kImage);
  ASSERT_EQ(color.codec, kOniCodecJpeg);
  const OniFrameRecord& damaged = color.frames.at(4);
  bytes.replace(damaged.payload_offset + damaged.payload_size / 2, 2, "\xFF\xD9");
  test::TempDir dir;
  test::WriteBytes(dir / "damaged.oni", bytes);
  const auto reference = ReadWithOwnReader(path);
  testing::internal::CaptureStderr();
  const auto frames = ReadWithOwnReader(dir / "damaged.oni");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(frames.size(), reference.size());
  int without_colour = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const bool paired = reference[i]->color_timestamp_us == std::int64_t(damaged.timestamp_us);
    without_colour += paired;
    EXPECT_EQ(frames[i]->rgb.empty(), paired) << i;
    if (!paired) EXPECT_EQ(frames[i]->rgb, reference[i]->rgb) << i;
    EXPECT_EQ(frames[i]->depth_mm, reference[i]->depth_mm) << i;
  }
  EXPECT_EQ(without_colour, 1);
}

TEST(OniReaderTest, RecoversEveryCompleteFrameOfATruncatedRecording) {
  const auto path = test::KinectRecording();
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent";
  const std::string bytes = test::ReadFileString(path);
  const OniIndex full = IndexOni(bytes, "full");
  ASSERT_TRUE(full.complete);
  const OniNode& depth = *full.FirstOfType(OniNodeType::kDepth);
  const auto reference = ReadWithOwnReader(path);
  test::TempDir dir;
  int files = 0;
  for (size_t cut = depth.frames.front().payload_offset + depth.frames.front().payload_size;
       cut < bytes.size(); cut += 97'531) {
    test::WriteBytes(dir / "cut.oni", bytes.substr(0, cut));
    size_t expected = 0;
    for (const OniFrameRecord& frame : depth.frames) {
      expected += frame.payload_offset + frame.payload_size <= cut;
    }
    OniFileSource source(dir / "cut.oni");
    const auto frames = test::ReadAllFrames(source);
    EXPECT_TRUE(source.Recovered()) << cut;
    ASSERT_EQ(frames.size(), expected) << "cut at " << cut;
    for (size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(frames[i]->depth_mm, reference[i]->depth_mm) << "cut " << cut << " frame " << i;
    }
    ++files;
  }
  EXPECT_GE(files, 15);
  // Cut before the first frame is complete: nothing to recover, a one-line error.
  test::WriteBytes(dir / "head.oni", bytes.substr(0, depth.frames.front().payload_offset + 10));
  try {
    OniFileSource(dir / "head.oni").Start();
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(
        std::string(error.what()).find("head.oni: the recording holds no complete depth frame"),
        std::string::npos)
        << error.what();
  }
}

TEST(OniReaderTest, RecoversOurOwnRecordingCutOffMidWrite) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(5, 160, 120);
  OniWriterOptions options;
  options.intrinsics = CameraIntrinsics::Carmine109().Scaled(160, 120);
  OniWriter writer(dir / "live.oni", options);
  for (const Frame& frame : frames) writer.Write(frame);
  // A crash now leaves the file as it is on disk: no seek tables, no END, counts unknown.
  std::filesystem::copy_file(dir / "live.oni", dir / "crashed.oni");
  writer.Close();
  OniFileSource source(dir / "crashed.oni");
  ExpectSameFrames(test::ReadAllFrames(source), frames);
  EXPECT_TRUE(source.Recovered());
  // The automatic input uses our reader; OpenNI2 opens such a file too (we write the node ids up
  // front) but knows no frame count, and ends the stream instead of hanging.
  auto input = OpenInput((dir / "crashed.oni").string());
  ExpectSameFrames(test::ReadAllFrames(*input), frames);
  EXPECT_TRUE(input->Recovered());
  SourceStatus end = SourceStatus::kFrame;
  const auto played = ReadWithOpenNi(dir / "crashed.oni", &end);
  EXPECT_EQ(end, SourceStatus::kEndOfStream);
  ExpectSameFrames(played, frames);
}

// Whether `path` is memory-mapped into this process.
bool Mapped(const std::filesystem::path& path) {
  return test::ReadFileString("/proc/self/maps").find(std::filesystem::canonical(path).string()) !=
         std::string::npos;
}

TEST(OniReaderTest, ARecordingCutWhileItPlaysIsAnInputErrorAndNeverMapped) {
  test::TempDir dir;
  const auto frames = test::MakePatternFrames(6, 160, 120);
  WriteOni(dir / "a.oni", frames, OniDepthCodec::k16zTable, 160, 120);
  OniFileSource source(dir / "a.oni");
  source.Start();
  // Read a piece at a time: memory does not grow with the file's size.
  EXPECT_FALSE(Mapped(dir / "a.oni"));
  for (int i = 0; i < 2; ++i) {
    const SourceRead read = source.Next(1s);
    ASSERT_EQ(read.status, SourceStatus::kFrame);
    EXPECT_EQ(read.frame->depth_mm, frames[i].depth_mm);
  }
  // Cut to half its size while it plays (a mapped file would raise SIGBUS here).
  std::filesystem::resize_file(dir / "a.oni", std::filesystem::file_size(dir / "a.oni") / 2);
  try {
    for (int i = 2; i < 6; ++i) source.Next(1s);
    FAIL() << "the frames past the cut were read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("a.oni: the file ends at byte"), std::string::npos)
        << error.what();
  }
}

TEST(OniReaderTest, NonRecordingsAndEmptyRecordingsGetOneLineErrors) {
  test::TempDir dir;
  struct Case {
    std::string name, bytes, needle;
  };
  std::string no_frames_path = (dir / "empty-recording.oni").string();
  WriteOni(no_frames_path, {}, OniDepthCodec::k16zTable);
  const Case cases[] = {
      {"empty.oni", "", "the file is empty"},
      {"text.oni", "this is not a recording at all, just some text", "not an .oni recording"},
      {"version.oni", std::string("NI10\x02\0\0\0", 8) + std::string(16, '\0'),
       "unsupported .oni version"},
  };
  for (const Case& c : cases) {
    test::WriteBytes(dir / c.name, c.bytes);
    try {
      OniFileSource(dir / c.name).Start();
      ADD_FAILURE() << c.name;
    } catch (const InputError& error) {
      const std::string text = error.what();
      EXPECT_NE(text.find(c.name + ": " + c.needle), std::string::npos) << text;
      EXPECT_EQ(text.find('\n'), std::string::npos) << text;
    }
  }
  EXPECT_THROW(OniFileSource(dir / "missing.oni").Start(), InputError);
  try {
    OniFileSource(no_frames_path).Start();
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("no complete depth frame"), std::string::npos);
  }
}

// Recordings with one byte changed at a seeded offset went, by default, to OpenNI2's file driver,
// which trusts the file's sizes and names: some crashed it in our process (SIGSEGV, a heap
// overflow). The automatic input reads them with our reader: each gives its frames or one
// InputError, never a crash (the sanitizer stage runs this too).
TEST(OniReaderTest, TheDefaultInputReadsDamagedRecordingsWithTheBuiltInReader) {
  test::TempDir dir;
  WriteOni(dir / "seed.oni", test::MakePatternFrames(4, 48, 36), OniDepthCodec::k16zTable, 48, 36);
  const std::string seed = test::ReadFileString(dir / "seed.oni");
  std::mt19937 rng = test::Rng(21);
  int played = 0, refused = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes = seed;
    bytes[rng() % bytes.size()] ^= static_cast<char>(1 + rng() % 255);
    const auto path = dir / "mutant.oni";
    test::WriteBytes(path, bytes);
    try {
      auto input = OpenInput(path.string());
      const auto frames = test::ReadAllFrames(*input);
      EXPECT_NE(input->Description().find("built-in reader"), std::string::npos)
          << input->Description();
      EXPECT_LE(frames.size() + input->SkippedFrames(), 4u) << trial;
      ++played;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << error.what();
      ++refused;
    }
  }
  EXPECT_EQ(played + refused, 300);
  EXPECT_GT(played, 150);  // Most single bytes lie in frame data or leave a readable prefix.
}

// Ten thousand mutated recordings: the reader must index and decode each without crashing,
// hanging or allocating without bound; the only failure it may report is an InputError.
TEST(OniReaderTest, SurvivesTenThousandMutatedRecordings) {
  test::TempDir dir;
  WriteOni(dir / "seed.oni", test::MakePatternFrames(3, 48, 36), OniDepthCodec::k16zTable, 48, 36);
  std::vector<std::string> seeds = {test::ReadFileString(dir / "seed.oni")};
  WriteOni(dir / "raw.oni", test::MakePatternFrames(2, 32, 24), OniDepthCodec::kUncompressed, 32,
           24);
  seeds.push_back(test::ReadFileString(dir / "raw.oni"));
  std::mt19937 rng = test::Rng(9);
  int indexed = 0, rejected = 0, decoded = 0;
  std::vector<std::uint16_t> depth;
  std::vector<std::uint8_t> rgb;
  for (int trial = 0; trial < 10'000; ++trial) {
    std::string bytes = seeds[trial % seeds.size()];
    const int mutations = 1 + rng() % 6;
    for (int m = 0; m < mutations; ++m) {
      const size_t at = rng() % bytes.size();
      switch (rng() % 5) {
        case 0:
          bytes[at] = static_cast<char>(rng());
          break;
        case 1:
          bytes[at] ^= static_cast<char>(1 << (rng() % 8));
          break;
        case 2:
          bytes.resize(std::max<size_t>(1, at));
          break;
        case 3:
          bytes.insert(at, std::string(1 + rng() % 16, static_cast<char>(rng())));
          break;
        default:  // A huge size field somewhere.
          if (at + 4 <= bytes.size()) {
            const std::uint32_t huge = 0xFFFFFF00u | (rng() & 0xFF);
            std::memcpy(bytes.data() + at, &huge, 4);
          }
      }
    }
    try {
      const OniIndex index = IndexOni(bytes, "mutant");
      ++indexed;
      for (const OniNode& node : index.nodes) {
        for (const OniFrameRecord& record : node.frames) {
          if (node.type == static_cast<std::int32_t>(OniNodeType::kDepth)) {
            decoded += DecodeOniDepth(bytes, node, record, depth);
            ASSERT_LE(depth.size(), static_cast<size_t>(8192) * 8192);
          } else {
            decoded += DecodeOniColor(bytes, node, record, rgb);
          }
        }
      }
    } catch (const InputError&) {
      ++rejected;
    }
  }
  EXPECT_EQ(indexed + rejected, 10'000);
  EXPECT_GT(indexed, 5'000);  // Most mutations leave the header intact.
  EXPECT_GT(decoded, 1'000);  // And many frames stay decodable.
}

}  // namespace
}  // namespace ihs::sensor
