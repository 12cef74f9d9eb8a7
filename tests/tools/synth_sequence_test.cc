// Whole synthetic sequences: the files written, their agreement with the ground truth, the
// command line, and determinism.

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/trajectory_io.h"
#include "render/offscreen_renderer.h"
#include "sensor/open_input.h"
#include "tests/source_reading.h"
#include "tests/test_util.h"
#include "tools/synth/object_shape.h"
#include "tools/synth/sequence.h"
#include "tracker/hand_data.h"
#include "tracker/hand_joints_io.h"

namespace ihs::synth {
namespace {

namespace fs = std::filesystem;

SequenceOptions ShortSequence() {
  SequenceOptions options;
  options.object = "sphere";
  options.scripted.frames = 60;
  options.last_frame = 23;  // Close, hold and part of the turn.
  return options;
}

std::vector<std::shared_ptr<const Frame>> ReadInput(const fs::path& input,
                                                    sensor::OniBackend backend) {
  sensor::InputOptions options;
  options.oni_backend = backend;
  auto source = sensor::OpenInput(input.string(), options);
  return test::ReadAllFrames(*source);
}

// Distances (mm) from the object's surface of the depth samples on object pixels.
std::vector<double> ObjectPixelErrors(const fs::path& out, const Frame& frame,
                                      const Rigid3& cam_from_object, const ObjectShape& object) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.png", static_cast<int>(frame.index));
  const cv::Mat labels = cv::imread((out / "gt" / "labels" / name).string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(labels.cols, frame.width);
  const CameraIntrinsics intrinsics;
  const Rigid3 object_from_cam = cam_from_object.Inverse();
  std::vector<double> errors;
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const std::uint16_t z = frame.depth_mm[static_cast<size_t>(v) * frame.width + u];
      if (labels.at<std::uint8_t>(v, u) != 2 || z == 0) continue;
      errors.push_back(
          std::abs(object.SignedDistance(object_from_cam * intrinsics.BackProject(u, v, z))));
    }
  }
  return errors;
}

double Quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0 : values[static_cast<size_t>(q * (values.size() - 1))];
}

TEST(SynthSequenceTest, IdealSequenceAgreesWithItsGroundTruth) {
  test::TempDir dir;
  SequenceOptions options = ShortSequence();
  options.sensor = SensorModelOptions::Ideal();
  const SequenceSummary summary = GenerateSequence(options, dir.path());
  EXPECT_EQ(summary.frames, 24);
  EXPECT_GT(summary.held_frames, 5);
  EXPECT_LT(summary.max_penetration_mm, 1.0);

  // The .oni and the TUM folder hold the same frames.
  const auto oni = ReadInput(dir / "sequence.oni", sensor::OniBackend::kOwnReader);
  const auto tum = ReadInput(dir / "tum", sensor::OniBackend::kAuto);
  ASSERT_EQ(oni.size(), 24u);
  ASSERT_EQ(tum.size(), 24u);
  for (size_t i = 0; i < oni.size(); ++i) {
    ASSERT_EQ(oni[i]->depth_mm, tum[i]->depth_mm) << "frame " << i;
    ASSERT_EQ(oni[i]->rgb, tum[i]->rgb) << "frame " << i;
  }

  // Object pixels lie on the object placed by the ground-truth trajectory (depth rounded to mm).
  const auto trajectory = ReadTumTrajectory(dir / "gt" / "trajectory.txt");
  ASSERT_EQ(trajectory.size(), 24u);
  const ObjectShape object = ObjectShape::FromSpec("sphere");
  for (size_t i = 0; i < oni.size(); i += 5) {
    const auto errors = ObjectPixelErrors(dir.path(), *oni[i], trajectory[i].transform, object);
    ASSERT_GT(errors.size(), 500u);
    EXPECT_LT(Quantile(errors, 0.99), 1.0) << "frame " << i;
  }

  // Touching fingertips (contacts.csv) have their end joint within a fingertip's thickness of
  // the surface; held frames have at least two of them.
  const auto joints = tracker::ReadHandJointsCsv(dir / "gt" / "hand_joints.csv");
  ASSERT_EQ(joints.size(), 24u);
  ASSERT_EQ(joints[0].joints_mm.size(), 21u);
  std::istringstream contacts(test::ReadFileString(dir / "gt" / "contacts.csv"));
  std::string line;
  std::getline(contacts, line);
  EXPECT_EQ(line.rfind("frame,held,pinky_touch,ring_touch,middle_touch,index_touch,thumb_touch", 0),
            0u);
  // Joint b + 1 is the end of bone b; the fingertip bones are 4, 8, 12, 16 (pinky … index) and
  // 19 (thumb).
  const int end_joint[5] = {5, 9, 13, 17, 20};
  int rows = 0, checked = 0;
  while (std::getline(contacts, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    ASSERT_EQ(fields.size(), 13u);
    const int frame = static_cast<int>(fields[0]);
    const Rigid3 object_from_cam = trajectory[frame].transform.Inverse();
    int touching = 0;
    for (int tip = 0; tip < 5; ++tip) {
      if (fields[2 + tip] != 1) continue;
      ++touching;
      const double d =
          object.SignedDistance(object_from_cam * joints[frame].joints_mm[end_joint[tip]]);
      EXPECT_LT(d, 15.0) << "frame " << frame << " fingertip " << tip;
      EXPECT_LE(fields[7 + tip], options.touch_mm);
      ++checked;
    }
    if (fields[1] == 1) {
      EXPECT_GE(touching, 2) << "frame " << frame;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 24);
  EXPECT_GT(checked, 10);

  const auto manifest = nlohmann::json::parse(test::ReadFileString(dir / "gt" / "manifest.json"));
  EXPECT_EQ(manifest["object"]["name"], "sphere");
  EXPECT_EQ(manifest["frames"]["count"], 24);
  EXPECT_EQ(manifest["sensor"]["depth_noise"], false);
  EXPECT_EQ(manifest["hand"], "procedural");
  EXPECT_TRUE(fs::exists(dir / "gt" / "object.ply"));
  EXPECT_TRUE(fs::exists(dir / "gt" / "intrinsics.json"));
  EXPECT_GT(fs::file_size(dir / "contact_sheet.png"), 10000u);
}

TEST(SynthSequenceTest, ARecordedMotionRendersTheDatasScannedHandAndSaysSo) {
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  SequenceOptions options;
  options.object = "sphere";
  options.motion = "recorded:" + (test::HandDataDir() / "sequences" / "004-sphere").string();
  options.last_frame = 44;  // Enough for the sphere's placement between thumb and index.
  const SequenceRenderer renderer(options);
  // The manifest's "hand" is the renderer's source: the data folder, not the default template.
  EXPECT_EQ(fs::path(renderer.hand_source()), test::HandDataDir());
  const tracker::HandModel procedural = tracker::LoadHandTemplate("procedural", true);
  EXPECT_NE(renderer.hand().rest_mesh.vertices.size(), procedural.rest_mesh.vertices.size());
}

TEST(SynthSequenceTest, OpenNiPlaysTheRecording) {
  test::TempDir dir;
  SequenceOptions options = ShortSequence();
  options.last_frame = 5;
  options.write_tum = false;
  GenerateSequence(options, dir.path());
  const auto frames = ReadInput(dir / "sequence.oni", sensor::OniBackend::kOpenNi);
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_EQ(frames[0]->width, 640);
  EXPECT_TRUE(frames[0]->HasColor());
}

TEST(SynthSequenceTest, NoisySequenceStaysNearTheSurfaceAndHasDropouts) {
  test::TempDir dir;
  SequenceOptions options = ShortSequence();
  options.last_frame = 9;
  options.write_tum = false;
  GenerateSequence(options, dir.path());
  const auto frames = ReadInput(dir / "sequence.oni", sensor::OniBackend::kOwnReader);
  ASSERT_EQ(frames.size(), 10u);
  const auto trajectory = ReadTumTrajectory(dir / "gt" / "trajectory.txt");
  const ObjectShape object = ObjectShape::FromSpec("sphere");
  const auto errors = ObjectPixelErrors(dir.path(), *frames[5], trajectory[5].transform, object);
  EXPECT_GT(Quantile(errors, 0.5), 0.1);  // Noise is there…
  EXPECT_LT(Quantile(errors, 0.5), 1.5);  // …of the size a Carmine has at 0.6 m.
}

TEST(SynthSequenceTest, SameSeedSameBytesOtherSeedOtherNoise) {
  test::TempDir dir;
  SequenceOptions options = ShortSequence();
  options.last_frame = 7;
  options.write_tum = false;
  GenerateSequence(options, dir / "a");
  GenerateSequence(options, dir / "b");
  options.seed = 2;
  GenerateSequence(options, dir / "c");
  for (const char* file : {"sequence.oni", "gt/trajectory.txt", "gt/contacts.csv",
                           "gt/hand_joints.csv", "gt/labels/000005.png"}) {
    EXPECT_EQ(test::ReadFileString(dir / "a" / file), test::ReadFileString(dir / "b" / file))
        << file;
  }
  EXPECT_NE(test::ReadFileString(dir / "a" / "sequence.oni"),
            test::ReadFileString(dir / "c" / "sequence.oni"));
}

TEST(SynthSequenceTest, AFrameStepRendersEveryNthFrameOfTheSameMotion) {
  SequenceOptions options = ShortSequence();
  options.sensor = SensorModelOptions::Ideal();
  SequenceRenderer every(options);
  options.frame_step = 3;
  SequenceRenderer third(options);
  ASSERT_EQ(every.frame_count(), 24);
  ASSERT_EQ(third.frame_count(), 8);
  for (int i : {1, 5, 7}) {
    const RenderedFrame fast = third.Render(i), slow = every.Render(3 * i);
    EXPECT_LT((fast.cam_from_object.translation() - slow.cam_from_object.translation()).norm(),
              1e-9);
    EXPECT_TRUE(fast.cam_from_object.rotation().isApprox(slow.cam_from_object.rotation(), 1e-12));
    EXPECT_LT((fast.joints_mm[20] - slow.joints_mm[20]).norm(), 1e-9);
    // The frame keeps its place in the faster sequence: index and time.
    EXPECT_EQ(fast.frame.index, i);
    EXPECT_EQ(fast.frame.depth_timestamp_us, std::llround(i * 1e6 / options.fps));
  }
  options.frame_step = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

// The same grasp with nothing in it: the hand's pixels and pose as with the object, no object
// pixel, no fingertip touching, nothing held.
TEST(SynthSequenceTest, AnEmptyHandMakesTheSameMotionWithNothingInIt) {
  SequenceOptions options = ShortSequence();
  options.sensor = SensorModelOptions::Ideal();
  SequenceRenderer holding(options);
  options.empty_hand = true;
  SequenceRenderer empty(options);
  int touching = 0;
  for (int i : {0, 12, 23}) {
    const RenderedFrame with = holding.Render(i), without = empty.Render(i);
    touching += with.contact.TouchingCount();
    const auto count = [](const RenderedFrame& r, std::uint8_t label) {
      return std::count(r.labels.begin(), r.labels.end(), label);
    };
    EXPECT_GT(count(with, render::kObject), 1000) << i;
    EXPECT_EQ(count(without, render::kObject), 0) << i;
    // The hand is the same or more of it shows (the object hid part of it).
    EXPECT_GE(count(without, render::kHand), count(with, render::kHand)) << i;
    EXPECT_LT((with.joints_mm[20] - without.joints_mm[20]).norm(), 1e-9) << i;
    EXPECT_EQ(without.contact.TouchingCount(), 0) << i;
    EXPECT_FALSE(without.held) << i;
  }
  EXPECT_GT(touching, 0) << "with the sphere in it, the grasp touches it";
}

test::CommandResult RunTool(const std::string& arguments) {
  return test::RunCommand(std::string(IHS_SYNTH_TOOL) + " " + arguments);
}

TEST(SynthToolTest, WritesTheLayoutAndRejectsBadOptionsInOneLine) {
  test::TempDir dir;
  const auto ok =
      RunTool("--preset demo --frames 0:4 --no-tum -q --out " + (dir / "demo").string());
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  for (const char* file :
       {"sequence.oni", "gt/trajectory.txt", "gt/object.ply", "gt/hand_joints.csv",
        "gt/contacts.csv", "gt/intrinsics.json", "gt/manifest.json", "contact_sheet.png"}) {
    EXPECT_TRUE(fs::exists(dir / "demo" / file)) << file;
  }
  EXPECT_EQ(ReadTumTrajectory(dir / "demo" / "gt" / "trajectory.txt").size(), 5u);
  // The demo's sample: the textured box, whose turn its mesh shows, a full turn in 180 frames.
  const auto manifest =
      nlohmann::json::parse(test::ReadFileString(dir / "demo" / "gt" / "manifest.json"));
  EXPECT_EQ(manifest["object"]["name"], "box");
  EXPECT_EQ(manifest["object"]["textured"], true);
  EXPECT_EQ(manifest["scripted"]["frames"], 180);
  EXPECT_EQ(manifest["scripted"]["turns"], 1.0);
  EXPECT_EQ(manifest["hand"], "procedural");

  const auto bad_object = RunTool("--object teapot --out " + (dir / "x").string());
  EXPECT_EQ(bad_object.exit_code, 2);
  EXPECT_EQ(std::count(bad_object.err.begin(), bad_object.err.end(), '\n'), 1) << bad_object.err;
  EXPECT_NE(bad_object.err.find("teapot"), std::string::npos);
  EXPECT_EQ(RunTool("--frames 9:x --out " + (dir / "x").string()).exit_code, 2);
  EXPECT_EQ(RunTool("--preset demo --frames 0:999 --out " + (dir / "x").string()).exit_code, 2);
  const auto missing =
      RunTool("--motion recorded:" + (dir / "nowhere").string() + " --out " + (dir / "x").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
}

}  // namespace
}  // namespace ihs::synth
