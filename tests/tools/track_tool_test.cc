// inhandscan-track on a short generated sequence: files written, errors measured, bad input.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/test_util.h"
#include "tools/synth/sequence.h"
#include "tracker/hand_joints_io.h"

namespace ihs {
namespace {

test::CommandResult RunTool(const std::string& arguments) {
  return test::RunCommand(std::string(IHS_TRACK_TOOL) + " " + arguments);
}

TEST(TrackToolTest, TracksAGeneratedSequenceAndMeasuresItsErrors) {
  test::TempDir dir;
  synth::SequenceOptions options;
  options.scripted.frames = 240;
  options.last_frame = 11;
  options.write_tum = false;
  synth::GenerateSequence(options, dir / "seq");
  const auto run =
      RunTool((dir / "seq" / "sequence.oni").string() + " --out " + (dir / "out").string() +
              " --gt " + (dir / "seq" / "gt").string() + " --init-from-gt -q");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("joint error:"), std::string::npos) << run.out;
  const auto joints = tracker::ReadHandJointsCsv(dir / "out" / "hand_joints.csv");
  EXPECT_EQ(joints.size(), 12u);
  const auto stats = nlohmann::json::parse(test::ReadFileString(dir / "out" / "stats.json"));
  EXPECT_EQ(stats["summary"]["frames"], 12);
  EXPECT_EQ(stats["frames"].size(), 12u);
  // The procedural hand tracking itself from the true start, in the scripted motion (the hand
  // mostly hidden behind the object): measured 8.2 mm over these 12 frames.
  EXPECT_LT(stats["summary"]["joint_error_mm_mean"].get<double>(), 15.0);
  EXPECT_NE(test::ReadFileString(dir / "out" / "contacts.csv").find("frame,status"),
            std::string::npos);
  // Each frame with contact pairs gives their median error; the summary pools them.
  int frames_with_contact_error = 0;
  for (const auto& frame : stats["frames"])
    frames_with_contact_error += frame.contains("contact_error_mm");
  EXPECT_EQ(frames_with_contact_error > 0, stats["summary"].contains("contact_error_mm_median"));

  // --set reaches the tracker: with a hand needing more points than a frame has, none is found.
  const auto strict =
      RunTool((dir / "seq" / "sequence.oni").string() + " --out " + (dir / "strict").string() +
              " --set tracker.min_hand_points=1000000 -q");
  ASSERT_EQ(strict.exit_code, 0) << strict.err;
  const auto strict_stats =
      nlohmann::json::parse(test::ReadFileString(dir / "strict" / "stats.json"));
  EXPECT_EQ(strict_stats["summary"]["status_counts"].size(), 1u) << strict_stats["summary"];
  EXPECT_EQ(strict_stats["summary"]["status_counts"].value("no_hand", 0), 12)
      << strict_stats["summary"];
}

TEST(TrackToolTest, BadInputAndOptionsGetOneLineErrors) {
  test::TempDir dir;
  const auto missing = RunTool((dir / "nothing.oni").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  const auto no_gt =
      RunTool((dir / "nothing.oni").string() + " --init-from-gt --out " + (dir / "o").string());
  EXPECT_EQ(no_gt.exit_code, 2) << no_gt.err;
  const auto bad_scale = RunTool("x.oni --hand-scale 9 --out " + (dir / "o").string());
  EXPECT_EQ(bad_scale.exit_code, 2);
  // --set takes the tracker's options only, each by a known name and a value of its type.
  for (const std::string& assignment :
       {"fusion.icp.anchor_share=1", "tracker.no_such_option=1", "tracker.fit.prior_weight=abc"}) {
    const auto bad_set = RunTool("x.oni --set " + assignment + " --out " + (dir / "o").string());
    EXPECT_EQ(bad_set.exit_code, 2) << assignment << ": " << bad_set.err;
    EXPECT_EQ(std::count(bad_set.err.begin(), bad_set.err.end(), '\n'), 1) << bad_set.err;
  }
}

}  // namespace
}  // namespace ihs
