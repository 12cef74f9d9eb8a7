// The hand-tracker stage on generator sequences: skipped frames, tracking from the ground truth,
// contacts, automatic initialisation, recovery after a jump, and the procedural template on the
// real hand's motion.

#include "tracker/hand_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "tests/test_util.h"
#include "tools/synth/sequence.h"
#include "tracker/hand_data.h"
#include "tracker/hand_joints_io.h"
#include "tracker/hand_search.h"
#include "tracker/procedural_hand.h"

namespace ihs::tracker {
namespace {

// A grasp as tools/bench_hand_init.sh draws it: the first frames of a scripted half turn.
struct DrawnGrasp {
  const char* object;
  std::uint32_t seed;
  double azimuth_deg, hand_scale, distance_mm, tilt_deg;
  bool left_hand;
};

synth::SequenceOptions DrawnGraspSequence(const DrawnGrasp& c, int last_frame) {
  synth::SequenceOptions sequence;
  sequence.object = c.object;
  sequence.seed = c.seed;
  sequence.scripted.seed = c.seed;
  sequence.scripted.frames = 160;
  sequence.scripted.turns = 0.5;
  sequence.scripted.start_azimuth_deg = c.azimuth_deg;
  sequence.scripted.distance_mm = c.distance_mm;
  sequence.scripted.tilt_deg = c.tilt_deg;
  sequence.hand_scale = c.hand_scale;
  sequence.left_hand = c.left_hand;
  sequence.last_frame = last_frame;
  return sequence;
}

synth::SequenceOptions RecordedSphere(int last_frame) {
  synth::SequenceOptions options;
  options.object = "sphere";
  options.motion = "recorded:" + (test::HandDataDir() / "sequences" / "004-sphere").string();
  options.last_frame = last_frame;
  return options;
}

TEST(HandTrackerTest, EmptyFramesAndFramesWithoutAHandAreSkippedWithAReason) {
  HandTracker tracker(MakeProceduralHand(), CameraIntrinsics());
  const TrackResult empty = tracker.Track(Frame::Blank(640, 480, true));
  EXPECT_EQ(empty.status, TrackStatus::kEmptyFrame);
  EXPECT_EQ(empty.reason, "empty depth image");
  EXPECT_FALSE(empty.HasPose());
  EXPECT_FALSE(empty.posed_mesh);
  // A blue square in the crop volume: an object, no hand.
  Frame frame = Frame::Blank(640, 480, true);
  for (int v = 200; v < 280; ++v) {
    for (int u = 280; u < 360; ++u) {
      frame.depth_mm[v * 640 + u] = 600;
      frame.rgb[3 * (v * 640 + u)] = 40, frame.rgb[3 * (v * 640 + u) + 1] = 60,
                               frame.rgb[3 * (v * 640 + u) + 2] = 200;
    }
  }
  const TrackResult no_hand = tracker.Track(frame);
  EXPECT_EQ(no_hand.status, TrackStatus::kNoHand);
  EXPECT_NE(no_hand.reason.find("no hand"), std::string::npos);
  EXPECT_EQ(no_hand.segmentation.object_points.size(), 6400u);
}

TEST(HandTrackerTest, TracksFromTheTruthAndFindsTheTouchingFingertips) {
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  synth::SequenceRenderer renderer(RecordedSphere(60));
  TrackerOptions options;
  options.scale_frames = 0;  // The rendered hand itself: its size is right.
  HandTracker tracker(renderer.hand(), renderer.options().intrinsics, options);
  tracker.Initialise(PoseFromBoneTransforms(renderer.hand(), renderer.Render(0).cam_from_bone));
  double error = 0;
  int true_positive = 0, predicted = 0, actual = 0, pairs = 0;
  const auto& ends = renderer.geometry().fingertip_bones();
  for (int i = 0; i < renderer.frame_count(); ++i) {
    const synth::RenderedFrame rendered = renderer.Render(i);
    const TrackResult result = tracker.Track(rendered.frame);
    ASSERT_TRUE(result.HasPose()) << "frame " << i << ": " << result.reason;
    // The posed template comes with the pose (the object mask uses it) and is the pose's.
    ASSERT_TRUE(result.posed_mesh) << "frame " << i;
    const TriangleMesh posed =
        tracker.model().Pose(ForwardKinematics(tracker.model(), result.pose));
    ASSERT_EQ(result.posed_mesh->vertices.size(), posed.vertices.size());
    EXPECT_LT((result.posed_mesh->vertices.front() - posed.vertices.front()).norm(), 1e-4f);
    EXPECT_LT((result.posed_mesh->vertices.back() - posed.vertices.back()).norm(), 1e-4f);
    error += MeanJointError(result.joints_mm, rendered.joints_mm);
    for (size_t e = 0; e < ends.size(); ++e) {
      const bool is = rendered.contact.fingertips[e].touching;
      const bool found =
          std::count(result.contacts.bones.begin(), result.contacts.bones.end(), ends[e]) > 0;
      true_positive += is && found, predicted += found, actual += is;
    }
    pairs += !result.contact_pairs.empty();
  }
  const int n = renderer.frame_count();
  std::printf(
      "mean joint error %.2f mm; contact bones precision %.2f recall %.2f; frames with "
      "contact pairs %d of %d\n",
      error / n, double(true_positive) / std::max(1, predicted),
      double(true_positive) / std::max(1, actual), pairs, n);
  // Measured: 1.94 mm; contact bones precision 1.00, recall 0.72 against fingertips whose skin
  // is within 2 mm of the surface (pinching from the side, the camera sees little of the object
  // under a fingertip); contact pairs in 36 of 61 frames.
  EXPECT_LT(error / n, 3.0);
  EXPECT_GT(double(true_positive) / std::max(1, predicted), 0.9);
  EXPECT_GT(double(true_positive) / std::max(1, actual), 0.4);
  EXPECT_GT(pairs, n / 2);
}

TEST(HandTrackerTest, EstimatesTheHandsScaleOverTheFirstFrames) {
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  synth::SequenceRenderer renderer(RecordedSphere(45));  // Only the first 12 frames are used.
  // The real hand is rendered; the tracker gets its template 8 % too small and too large, and
  // 30 % too large: beyond the estimate's range, which says so.
  for (double template_scale : {0.92, 1.08, 1.3}) {
    const HandModel model = renderer.hand().Scaled(template_scale);
    HandTracker tracker(model, renderer.options().intrinsics);
    ASSERT_TRUE(tracker.estimating_scale());
    tracker.Initialise(FitPoseToJoints(model, renderer.Render(0).joints_mm));
    TrackResult result;
    for (int i = 0; i < 12; ++i) result = tracker.Track(renderer.Render(i).frame);
    EXPECT_FALSE(tracker.estimating_scale());
    EXPECT_EQ(result.hand_scale, tracker.scale());
    const double hand = template_scale * tracker.scale();
    std::printf("template %.2f: scale %.3f, the hand %.3f of its true size\n", template_scale,
                tracker.scale(), hand);
    if (template_scale > 1.2) {
      EXPECT_TRUE(tracker.scale_at_bound());
      EXPECT_NEAR(tracker.scale(), 1.0 - tracker.options().scale_range, 1e-9);
      continue;
    }
    EXPECT_FALSE(tracker.scale_at_bound());
    // Measured: 0.953 and 1.009. The estimate comes out a few per cent small: the sensor loses
    // depth at the silhouette's edge, so the hand looks thinner than it is.
    EXPECT_NEAR(hand, 1.0, 0.06);
    // The frame after the switch to the estimated scale: measured 4.21 and 6.16 mm (with four
    // correspondence updates per frame instead of three, 4.34 and 5.90).
    EXPECT_LT(MeanJointError(result.joints_mm, renderer.Render(11).joints_mm), 6.5);
  }
}

TEST(HandTrackerTest, TheScaleEstimateBesideTheTrackingGivesTheSameScaleAFrameLater) {
  // Live (search_beside), each frame's fits at the candidate scales run on their own thread
  // while the tracker goes on at the template's size: waited for after each frame (so that each
  // is weighed on the next), the estimate is the one made in place, switched to a frame later.
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  synth::SequenceRenderer renderer(RecordedSphere(45));
  const HandModel model = renderer.hand().Scaled(1.08);
  auto run = [&](bool beside, int* switched_at) {
    TrackerOptions options;
    options.search_beside = beside;
    HandTracker tracker(model, renderer.options().intrinsics, options);
    tracker.Initialise(FitPoseToJoints(model, renderer.Render(0).joints_mm));
    for (int i = 0; i < 13 && tracker.estimating_scale(); ++i) {
      tracker.Track(renderer.Render(i).frame);
      tracker.FinishSearch();
      *switched_at = i;
    }
    EXPECT_FALSE(tracker.estimating_scale());
    return tracker.scale();
  };
  int in_place_at = -1, beside_at = -1;
  const double in_place = run(false, &in_place_at), beside = run(true, &beside_at);
  std::printf("scale %.4f at frame %d in place, %.4f at frame %d beside\n", in_place, in_place_at,
              beside, beside_at);
  EXPECT_EQ(beside, in_place);
  EXPECT_EQ(in_place_at, TrackerOptions().scale_frames - 1);
  EXPECT_EQ(beside_at, in_place_at + 1);
}

// An injected jump: the pose of `rendered`'s hand 80 mm and 40° away, as a tracker may come to
// believe it.
HandPose JumpedPose(const HandModel& hand, const synth::RenderedFrame& rendered) {
  HandPose wrong = PoseFromBoneTransforms(hand, rendered.cam_from_bone);
  wrong.cam_from_root =
      Rigid3::FromAxisAngle(Eigen::Vector3d(1, 1, 0), 0.7, Eigen::Vector3d(80, 0, 0)) *
      wrong.cam_from_root;
  return wrong;
}

TEST(HandTrackerTest, InitialisesFromTheOpenHandAndRecoversAfterAJump) {
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  synth::SequenceRenderer renderer(RecordedSphere(45));
  HandTracker tracker(renderer.hand(), renderer.options().intrinsics);
  std::vector<double> errors;
  for (int i = 0; i < renderer.frame_count(); ++i) {
    const synth::RenderedFrame rendered = renderer.Render(i);
    if (i == 25) tracker.Initialise(JumpedPose(renderer.hand(), rendered));
    const TrackResult result = tracker.Track(rendered.frame);
    errors.push_back(MeanJointError(result.joints_mm, rendered.joints_mm));
    std::printf("frame %d: %s, joint error %.1f mm, coverage %.2f\n", i, ToString(result.status),
                errors.back(), result.fit.data_coverage);
  }
  EXPECT_LT(errors[0], 15.0);  // From the open hand alone.
  double after = 0;
  for (int i = 35; i < renderer.frame_count(); ++i) after += errors[i];
  EXPECT_LT(after / (renderer.frame_count() - 35), 10.0);  // Recovered within 10 frames.
}

TEST(HandTrackerTest, ASearchBesideTheTrackingLeavesItGoingAndIsWeighedOnceDone) {
  // Live (search_beside), the search a jump's doubtful fits start runs on its own thread: the
  // frame that starts it keeps its tracked fit, it is not searched in place; once it is done, the
  // next frame weighs its pose (moved on by the tracked motion) against the tracked fit, and it
  // wins. Started from the truth, at the template's size, over 16 frames: a quick case for the
  // sanitizers.
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  synth::SequenceRenderer renderer(RecordedSphere(45));
  TrackerOptions options;
  options.search_beside = true;
  options.scale_frames = 0;
  HandTracker tracker(renderer.hand(), renderer.options().intrinsics, options);
  constexpr int kFirst = 30, kJump = 34;  // Frames 30-45 only.
  std::vector<double> errors;
  int started_at = -1, weighed_at = -1;
  for (int i = kFirst; i < renderer.frame_count(); ++i) {
    const synth::RenderedFrame rendered = renderer.Render(i);
    if (i == kFirst) {
      tracker.Initialise(PoseFromBoneTransforms(renderer.hand(), rendered.cam_from_bone));
    }
    if (i == kJump) tracker.Initialise(JumpedPose(renderer.hand(), rendered));
    const bool was_searching = tracker.searching();
    const TrackResult result = tracker.Track(rendered.frame);
    errors.push_back(MeanJointError(result.joints_mm, rendered.joints_mm));
    std::printf("frame %d: %s, joint error %.1f mm%s\n", i, ToString(result.status), errors.back(),
                tracker.searching() ? ", searching beside" : "");
    if (!was_searching && tracker.searching()) {
      started_at = i;
      // Not searched in place: the frame keeps the tracked fit (here diverged, 467 mm off).
      EXPECT_NE(result.status, TrackStatus::kInitialised) << "frame " << i;
      EXPECT_GT(errors.back(), 100.0) << "frame " << i;
      tracker.FinishSearch();
    }
    if (was_searching && !tracker.searching()) {
      weighed_at = i;
      EXPECT_EQ(result.status, TrackStatus::kInitialised) << "frame " << i;
    }
  }
  ASSERT_GE(started_at, kJump);
  EXPECT_LE(started_at, kJump + 3);
  EXPECT_EQ(weighed_at, started_at + 1);
  // Within a finger's width from the frame after.
  for (int i = weighed_at + 1; i < renderer.frame_count(); ++i) {
    EXPECT_LT(errors[i - kFirst], 10.0) << "frame " << i;
  }
}

TEST(HandTrackerTest, AFitTurnedOverMidSequenceIsDoubtedAndTurnedBackWithinAFewFrames) {
  // The procedural hand turning the sphere, tracked from the truth; at frame 12 the tracker is
  // told the hand turned over (palm for back), as a wrong search or a fast turn could leave it.
  synth::SequenceOptions sequence;
  sequence.scripted.frames = 36;
  sequence.scripted.turns = 0.25;
  synth::SequenceRenderer renderer(sequence);
  struct Outcome {
    int over = 0;                     // Frames turned over against the truth, or without a pose.
    int last_over = -1;               // The last of them.
    bool trusted_while_over = false;  // A turned-over pose given as tracked, undoubted.
  };
  // `beside`: the search and the flip check run beside the tracking, as live (each waited for
  // after its frame, so that the next frame weighs it: the run is the same every time).
  auto run = [&](bool recover, bool beside = false) {
    TrackerOptions options;
    options.scale_frames = 0;
    options.search_beside = beside;
    if (!recover) options.flip_check_frames = 0, options.doubtful_frames_to_search = 1000;
    HandTracker tracker(renderer.hand(), renderer.options().intrinsics, options);
    tracker.Initialise(FitPoseToJoints(renderer.hand(), renderer.Render(0).joints_mm));
    Outcome outcome;
    for (int i = 0; i < renderer.frame_count(); ++i) {
      const synth::RenderedFrame rendered = renderer.Render(i);
      if (i == 12) {
        tracker.Initialise(
            TurnedOver(renderer.hand(), FitPoseToJoints(renderer.hand(), rendered.joints_mm)));
      }
      const TrackResult result = tracker.Track(rendered.frame);
      if (beside) tracker.FinishSearch();
      if (!result.HasPose() ||
          CompareHandSides(renderer.hand(), result.joints_mm, rendered.joints_mm).turned_over()) {
        ++outcome.over, outcome.last_over = i;
        outcome.trusted_while_over |= result.HasPose() && !result.doubtful;
      }
    }
    std::printf("%s%s: %d frames turned over or lost, the last %d\n",
                recover ? "searching and checking the flip" : "neither",
                beside ? " beside the tracking" : "", outcome.over, outcome.last_over);
    return outcome;
  };
  const Outcome recovered = run(true);
  const int within = TrackerOptions().flip_check_frames;
  EXPECT_LE(recovered.over, within);
  EXPECT_LT(recovered.last_over, 12 + within);
  EXPECT_FALSE(recovered.trusted_while_over);
  // Beside the tracking, a frame later at most.
  const Outcome beside = run(true, true);
  EXPECT_LE(beside.over, within + 1);
  EXPECT_LT(beside.last_over, 12 + within + 1);
  EXPECT_FALSE(beside.trusted_while_over);
  // Neither searching nor checking, the fit stays turned over, or lost, for the rest.
  EXPECT_GT(run(false).over, (renderer.frame_count() - 12) / 2);
}

TEST(HandTrackerTest, TheFlipCheckBesideTheTrackingLeavesItsFrameAndIsWeighedOnTheNext) {
  // Live (search_beside), the periodic check of the fit turned over runs on its own thread: the
  // frame it is due on is not held up, the next frame weighs it. Tracked from the truth, the
  // turned-over fit never wins, so the hands are the same as with the check in place.
  synth::SequenceOptions sequence;
  sequence.scripted.frames = 12;
  sequence.scripted.turns = 0.05;
  synth::SequenceRenderer renderer(sequence);
  struct Run {
    std::vector<std::vector<Eigen::Vector3d>> joints;
    std::vector<int> started, weighed;  // Frames a check began on beside, and was weighed on.
  };
  auto run = [&](bool beside) {
    TrackerOptions options;
    options.scale_frames = 0;
    options.flip_check_frames = 3;
    options.search_beside = beside;
    HandTracker tracker(renderer.hand(), renderer.options().intrinsics, options);
    tracker.Initialise(FitPoseToJoints(renderer.hand(), renderer.Render(0).joints_mm));
    Run out;
    for (int i = 0; i < renderer.frame_count(); ++i) {
      const bool was_checking = tracker.checking_flip();
      const TrackResult result = tracker.Track(renderer.Render(i).frame);
      EXPECT_EQ(result.status, TrackStatus::kTracked) << "frame " << i;
      EXPECT_FALSE(result.turned_over) << "frame " << i;
      if (!was_checking && tracker.checking_flip()) out.started.push_back(i);
      if (was_checking && !tracker.checking_flip()) out.weighed.push_back(i);
      tracker.FinishSearch();  // The next frame weighs it: the run is the same every time.
      out.joints.push_back(result.joints_mm);
    }
    return out;
  };
  const Run in_place = run(false), beside = run(true);
  EXPECT_TRUE(in_place.started.empty());
  ASSERT_EQ(beside.started, (std::vector<int>{2, 5, 8, 11}));  // The last one never weighed.
  EXPECT_EQ(beside.weighed, (std::vector<int>{3, 6, 9}));
  for (int i = 0; i < renderer.frame_count(); ++i)
    EXPECT_EQ(in_place.joints[i], beside.joints[i]) << "frame " << i;
}

}  // namespace
}  // namespace ihs::tracker

namespace ihs::tracker {
namespace {

TEST(HandTrackerTest, ALeftHandIsTrackedWithTheMirroredTemplate) {
  synth::SequenceOptions options;  // The procedural hand, mirrored, turning the sphere.
  options.left_hand = true;
  options.scripted.frames = 40;
  options.scripted.turns = 0.25;
  synth::SequenceRenderer renderer(options);
  auto mean_joint_error = [&](const HandModel& model) {
    TrackerOptions tracker_options;
    tracker_options.scale_frames = 0;
    HandTracker tracker(model, renderer.options().intrinsics, tracker_options);
    tracker.Initialise(FitPoseToJoints(model, renderer.Render(0).joints_mm));
    double error = 0;
    for (int i = 0; i < renderer.frame_count(); ++i) {
      const synth::RenderedFrame rendered = renderer.Render(i);
      error += MeanJointError(tracker.Track(rendered.frame).joints_mm, rendered.joints_mm);
    }
    return error / renderer.frame_count();
  };
  const double left = mean_joint_error(LoadHandTemplate("procedural", false));
  const double right = mean_joint_error(MakeProceduralHand());
  std::printf("left hand: %.2f mm with the left template, %.2f mm with the right one\n", left,
              right);
  // Measured 3.5 mm with the left template, 60.0 mm with the right one.
  EXPECT_LT(left, 6.0);
  EXPECT_GT(right, 3 * left);
}

TEST(HandTrackerTest, SearchesForTheHandAnewWhenItsFitsGrowDoubtful) {
  // The scripted motion swings the hand back 90° around a water bottle between grasps (about
  // 10 mm per frame at the joints, the hand mostly behind the bottle): the tracker loses it
  // there, and fits that put the hand in the wrong place still explain 75–95 % of its points.
  synth::SequenceOptions options;
  options.object = "water-bottle";
  options.seed = options.scripted.seed = 5;
  options.last_frame = 130;
  synth::SequenceRenderer renderer(options);
  int doubtful_frames = 0;
  auto late_joint_error = [&](double search_data_coverage) {
    TrackerOptions tracker_options;
    tracker_options.scale_frames = 0;
    tracker_options.search_data_coverage = search_data_coverage;
    // The searches alone (the thumb check is off by default): with it as well the two runs
    // measured 16.9 and 18.1 mm over frames 90-130 (docs/tracker.md).
    tracker_options.thumb_check = false;
    HandTracker tracker(renderer.hand(), renderer.options().intrinsics, tracker_options);
    tracker.Initialise(FitPoseToJoints(renderer.hand(), renderer.Render(0).joints_mm));
    double error = 0;
    int frames = 0, searched = 0, doubtful = 0;
    for (int i = 0; i < renderer.frame_count(); ++i) {
      const synth::RenderedFrame rendered = renderer.Render(i);
      const TrackResult result = tracker.Track(rendered.frame);
      searched += i > 0 && result.status == TrackStatus::kInitialised;
      // A doubtful pose is one given whose fit explains too little, or as little as the fit
      // turned over; it is said.
      EXPECT_EQ(
          result.doubtful,
          result.HasPose() && (result.fit.data_coverage < search_data_coverage || result.flip_tie))
          << "frame " << i;
      EXPECT_EQ(result.State().find("(doubtful)") != std::string::npos, result.doubtful);
      doubtful += result.doubtful;
      if (i >= 90) error += MeanJointError(result.joints_mm, rendered.joints_mm), ++frames;
    }
    std::printf(
        "search below %.2f: joint error %.1f mm over frames 90-130, %d searches won, %d frames "
        "doubtful\n",
        search_data_coverage, error / frames, searched, doubtful);
    doubtful_frames = doubtful;
    return error / frames;
  };
  const double searching = late_joint_error(TrackerOptions().search_data_coverage);
  // The swings back around the bottle leave the fit doubtful in some frames (measured 4 of
  // 131), not in most.
  EXPECT_GT(doubtful_frames, 0);
  EXPECT_LT(doubtful_frames, renderer.frame_count() / 2);
  // Searching only once the fits have diverged (below min_data_coverage), as before.
  const double diverged_only = late_joint_error(TrackerOptions().min_data_coverage);
  // Measured 10.8 mm searching, 33.7 mm searching only once diverged (12.1 and 33.5 mm with the
  // thumb's opposition in the scores, grasp_side.opposition_weight 10; 15.6 and 91.7 mm with
  // every n-th hand point as data instead of the cubes' centroids).
  EXPECT_LT(searching, 30.0);
  EXPECT_GT(diverged_only, 2 * searching);
}

TEST(HandTrackerTest, TheProceduralTemplateFollowsTheRealHand) {
  if (test::HandDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  synth::SequenceRenderer renderer(RecordedSphere(60));
  const HandModel procedural = MakeProceduralHand();
  // Benchmark mode: the template takes over the true first pose through the joints.
  const HandPose start = FitPoseToJoints(procedural, renderer.Render(0).joints_mm);
  const double start_error =
      MeanJointError(procedural.JointPositions(ForwardKinematics(procedural, start)),
                     renderer.Render(0).joints_mm);
  HandTracker tracker(procedural, renderer.options().intrinsics);
  tracker.Initialise(start);
  double error = 0;
  for (int i = 0; i < renderer.frame_count(); ++i) {
    const synth::RenderedFrame rendered = renderer.Render(i);
    const TrackResult result = tracker.Track(rendered.frame);
    error += MeanJointError(result.joints_mm, rendered.joints_mm);
  }
  std::printf("procedural template: start %.2f mm, mean joint error %.2f mm over %d frames\n",
              start_error, error / renderer.frame_count(), renderer.frame_count());
  // Measured: start 2.51 mm, 7.0 mm mean over frames 0–60 (7.4 mm over 0–299 and 7.5 mm over
  // the whole session with inhandscan-track; the target is 10 mm): the template's
  // proportions differ from the real hand's (docs/tracker.md, "Known limits").
  EXPECT_LT(start_error, 5.0);
  EXPECT_LT(error / renderer.frame_count(), 10.0);
}

}  // namespace
}  // namespace ihs::tracker

namespace ihs::tracker {
namespace {

TEST(HandTrackerTest, AThumbAmongTheFingersIsTriedAcrossTheHeldObject) {
  // tools/bench_hand_init.sh 8200's case18: a right hand holding a bowling pin. By depth alone
  // its thumb, hidden behind the pin, was fitted on the fingers' side from frame 16 on (its tip
  // nearer the true little fingertip than the true thumb tip in every frame after). A hand holds
  // what it holds between its thumb and its fingers (GraspSide::Opposition): with the thumb
  // check, such a thumb is started across the object and fitted, and kept there. The frame
  // it moves stays tracked (the rest of the hand is the previous one moved: its motion still
  // carries the held object), and the thumb's contacts are not paired across it.
  const DrawnGrasp c{"bowling-pin", 8218, 8, 1.03, 658, 2, false};
  synth::SequenceRenderer renderer(DrawnGraspSequence(c, 34));
  int moved = 0, moved_tracked = 0, thumb_pairs = 0;
  auto swapped = [&](bool check) {
    TrackerOptions options;
    options.thumb_check = check;
    options.grasp_side.opposition_weight = check ? 10.0 : 0.0;
    HandTracker tracker(MakeProceduralHand(), renderer.options().intrinsics, options);
    int frames = 0;
    for (int i = 0; i < renderer.frame_count(); ++i) {
      const synth::RenderedFrame rendered = renderer.Render(i);
      const TrackResult result = tracker.Track(rendered.frame);
      EXPECT_TRUE(result.HasPose()) << "frame " << i;
      if (i >= 25 && result.HasPose() &&
          CompareHandSides(tracker.model(), result.joints_mm, rendered.joints_mm).thumb_swapped)
        ++frames;
      if (!result.thumb_moved) continue;
      ++moved;
      moved_tracked += result.status == TrackStatus::kTracked;
      const ContactDetector detector(tracker.model());
      const std::vector<int> ends = tracker.model().EndEffectors();
      for (size_t k = 0; k < ends.size(); ++k) {
        if (tracker.model().FingerOf(ends[k]) != 4) continue;
        const std::vector<int>& thumb = detector.fingertip_vertices()[k];
        for (const ContactPair& pair : result.contact_pairs)
          thumb_pairs += std::count(thumb.begin(), thumb.end(), pair.vertex) > 0;
      }
    }
    return frames;
  };
  const int with_check = swapped(true), without = swapped(false);
  std::printf(
      "thumb on the fingers' side in %d of frames 25-34 with the thumb check, %d without; the "
      "check moved it in %d frames, %d of them tracked\n",
      with_check, without, moved, moved_tracked);
  EXPECT_GE(without, 5);
  EXPECT_EQ(with_check, 0);
  EXPECT_GE(moved, 1);
  EXPECT_EQ(moved_tracked, moved);
  EXPECT_EQ(thumb_pairs, 0);
}

TEST(HandTrackerTest, AHandHoldingAnObjectIsNotInitialisedPalmForBack) {
  // Two generated grasps (drawn by tools/bench_hand_init.sh 7000: its case23 and case14) whose
  // self-initialised fit, by depth alone, turned the hand palm for back from the first frame
  // (59.9 and 64.7 mm joint error over 61 frames, palm for back in 57 and 43 of them). The
  // object lies on the palm's side of a holding hand (GraspSide): with that prior, neither is
  // (its weight at 0 also leaves out the search's starts that hold the object).
  for (const DrawnGrasp& c : {DrawnGrasp{"bowling-pin", 7023, 20, 0.95, 416, 27, false},
                              DrawnGrasp{"box", 7014, 71, 0.91, 419, 4, false}}) {
    synth::SequenceRenderer renderer(DrawnGraspSequence(c, 2));
    auto palm_for_back = [&](double weight) {
      TrackerOptions options;
      options.scale_frames = 0;  // The first frames run at the template's size anyway.
      options.grasp_side.weight = weight;
      HandTracker tracker(MakeProceduralHand(), renderer.options().intrinsics, options);
      int reversed = 0;
      for (int i = 0; i < renderer.frame_count(); ++i) {
        const synth::RenderedFrame rendered = renderer.Render(i);
        const TrackResult result = tracker.Track(rendered.frame);
        EXPECT_TRUE(result.HasPose()) << c.object << " frame " << i;
        if (result.HasPose() &&
            CompareHandSides(tracker.model(), result.joints_mm, rendered.joints_mm).palm_reversed)
          ++reversed;
      }
      return reversed;
    };
    const int with_prior = palm_for_back(GraspSideOptions().weight);
    std::printf("%s: palm for back in %d of %d frames with the grasp side, %d without\n", c.object,
                with_prior, renderer.frame_count(), palm_for_back(0.0));
    EXPECT_EQ(with_prior, 0) << c.object;
  }
}

}  // namespace
}  // namespace ihs::tracker

namespace ihs::tracker {
namespace {

TEST(HandTrackerTest, AHandHoldingAnObjectIsFoundFromStartsThatHoldIt) {
  // Two generated left-hand grasps (tools/bench_hand_init.sh 7000's case16 and 1000's case07)
  // that the search's even orientations found 106–109 mm off on their first frame. With starts
  // that hold the object in the palm (HandSearchOptions::grasp_rolls) within 40 mm (measured
  // 27 and 28 mm): not yet a fit within 10 mm, but in the truth's neighbourhood.
  for (const DrawnGrasp& c : {DrawnGrasp{"water-bottle", 7016, -87, 1.13, 467, 11, true},
                              DrawnGrasp{"bowling-pin", 1007, -65, 1.16, 560, 39, true}}) {
    synth::SequenceRenderer renderer(DrawnGraspSequence(c, 0));
    const synth::RenderedFrame rendered = renderer.Render(0);
    ProceduralHandOptions left;
    left.right_hand = false;
    auto first_frame_error = [&](int grasp_rolls) {
      TrackerOptions options;
      options.scale_frames = 0;  // The first frame is searched at the template's size anyway.
      options.search.grasp_rolls = grasp_rolls;
      HandTracker tracker(MakeProceduralHand(left), renderer.options().intrinsics, options);
      const TrackResult result = tracker.Track(rendered.frame);
      EXPECT_TRUE(result.HasPose()) << c.object;
      return result.HasPose() ? MeanJointError(result.joints_mm, rendered.joints_mm) : 1e9;
    };
    const double with_starts = first_frame_error(HandSearchOptions().grasp_rolls);
    std::printf("%s: first frame %.1f mm with starts that hold it, %.1f mm without\n", c.object,
                with_starts, first_frame_error(0));
    EXPECT_LT(with_starts, 40.0) << c.object;
  }
}

}  // namespace
}  // namespace ihs::tracker

namespace ihs::tracker {
namespace {

TEST(HandTrackerTest, AHandFirstSeenBehindTheObjectIsSearchedAgainOnceMoreOfItShows) {
  // A generated left-hand grasp (tools/bench_hand_init.sh 9100's case18): on the first frame
  // the hand is mostly hidden behind the small bottle, and the search placed what shows of it
  // 98 mm from the truth, where it was tracked on (89-91 mm over frames 10-60). With
  // search_when_points_grow (off by default: docs/tracker.md), once a frame shows 1.25 times
  // the points of the first, a search runs again and its pose, scoring much better, replaces
  // the tracked one.
  const DrawnGrasp c{"small-bottle", 9118, -69, 0.92, 430, 36, true};
  synth::SequenceRenderer renderer(DrawnGraspSequence(c, 45));
  ProceduralHandOptions left;
  left.right_hand = false;
  auto last_frames_error = [&](double grow) {
    TrackerOptions options;
    options.search_when_points_grow = grow;
    HandTracker tracker(MakeProceduralHand(left), renderer.options().intrinsics, options);
    double error = 0;
    for (int i = 0; i < renderer.frame_count(); ++i) {
      const synth::RenderedFrame rendered = renderer.Render(i);
      const TrackResult result = tracker.Track(rendered.frame);
      if (i >= renderer.frame_count() - 5) {
        EXPECT_TRUE(result.HasPose()) << "frame " << i;
        error += result.HasPose() ? MeanJointError(result.joints_mm, rendered.joints_mm) / 5 : 1e9;
      }
    }
    return error;
  };
  const double searched = last_frames_error(1.25);
  const double kept = last_frames_error(0);
  std::printf("frames 41-45: %.1f mm with the search as the hand shows, %.1f mm without\n",
              searched, kept);
  EXPECT_LT(searched, 15.0);
  EXPECT_GT(kept, 50.0);  // Without it the first frame's misplaced fit stays.
}

}  // namespace
}  // namespace ihs::tracker
