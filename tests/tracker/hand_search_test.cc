// The hand tracker's global search: curled articulations, and the true pose found among many
// orientations from the hand points alone (hands seen from the side, from the palm's side and
// from the back).

#include "tracker/hand_search.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <set>
#include <vector>

#include "tools/synth/sequence.h"
#include "tracker/hand_fit.h"
#include "tracker/hand_tracker.h"
#include "tracker/procedural_hand.h"
#include "tracker/segmentation.h"

namespace ihs::tracker {
namespace {

// `pose` of `hand` seen as a z-buffer of its vertices (3×3 pixel splats) in `frame` (blank,
// 640 × 480): returns the vertices that z-buffer shows.
std::vector<Eigen::Vector3f> SplatHand(const HandModel& hand, const HandPose& pose,
                                       const CameraIntrinsics& intrinsics, Frame* frame) {
  const std::vector<Eigen::Vector3f> vertices = hand.Pose(ForwardKinematics(hand, pose)).vertices;
  auto pixel = [&](const Eigen::Vector3f& v) {
    const Eigen::Vector2d uv = intrinsics.Project(v.cast<double>());
    return Eigen::Vector2i(static_cast<int>(std::lround(uv.x())),
                           static_cast<int>(std::lround(uv.y())));
  };
  for (const Eigen::Vector3f& v : vertices) {
    const Eigen::Vector2i p = pixel(v);
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        std::uint16_t& depth = frame->depth_mm[(p.y() + dv) * 640 + p.x() + du];
        const auto z = static_cast<std::uint16_t>(std::lround(v.z()));
        if (depth == 0 || z < depth) depth = z;
      }
    }
  }
  std::vector<Eigen::Vector3f> visible;
  for (const Eigen::Vector3f& v : vertices) {
    const Eigen::Vector2i p = pixel(v);
    if (v.z() < frame->DepthAt(p.x(), p.y()) + 3.0f) visible.push_back(v);
  }
  return visible;
}

TEST(HandSearchTest, ACurledHandsFingertipsComeTowardThePalm) {
  const HandModel hand = MakeProceduralHand();
  auto tip_to_wrist = [&](double curl) {
    const std::vector<Eigen::Vector3d> joints =
        hand.JointPositions(ForwardKinematics(hand, CurledHand(hand, curl)));
    double sum = 0;
    for (const Eigen::Vector3d& joint : joints) sum += (joint - joints.front()).norm();
    return sum / joints.size();
  };
  EXPECT_GT(tip_to_wrist(0.0), tip_to_wrist(0.4) + 5.0);
  EXPECT_GT(tip_to_wrist(0.4), tip_to_wrist(0.8) + 5.0);
  // Within the limits: a full curl is each joint's flexion limit.
  const HandPose fist = CurledHand(hand, 1.0);
  const std::vector<DegreeOfFreedom> dofs = JointDegreesOfFreedom(hand);
  for (size_t k = 0; k < dofs.size(); ++k) {
    const auto& range = hand.limits[dofs[k].bone].limits_deg[dofs[k].axis];
    EXPECT_GE(fist.angles_rad[k] * 180 / M_PI, range.first - 1e-9);
    EXPECT_LE(fist.angles_rad[k] * 180 / M_PI, std::max(0.0, range.second) + 1e-9);
  }
}

TEST(HandSearchTest, FindsTheTruePoseAmongManyOrientationsFromTheHandPointsAlone) {
  // The scripted grasp of a box (seed 17), the hand beside it (the default start) and 60°
  // earlier round it, in front of the box with its back to the camera. Not yet found: 90°
  // farther round, behind the box, where only the thumb and part of the back of the hand show
  // and the fingertips at the box's edge are not among the hand points: the truth placed from
  // itself scores 11.8, better than the 14.8 of the best hypothesis found (117° off), but no
  // start reaches the truth's basin (issue 32).
  for (double azimuth : {0.0, -60.0}) {
    synth::SequenceOptions options;
    options.object = "box";
    options.scripted.frames = 60;
    options.scripted.turns = 0.25;
    options.scripted.start_azimuth_deg = azimuth;
    options.seed = 17;
    options.last_frame = 8;
    synth::SequenceRenderer renderer(options);
    const synth::RenderedFrame rendered = renderer.Render(8);
    const HandPose truth = PoseFromBoneTransforms(renderer.hand(), rendered.cam_from_bone);
    const Segmentation segmentation =
        Segmenter(renderer.options().intrinsics, SegmentationOptions()).Segment(rendered.frame);
    ASSERT_GT(segmentation.hand_points.size(), 500u) << "azimuth " << azimuth;

    // The true articulation among curled ones, its root pose withheld.
    HandPose articulation = truth;
    articulation.cam_from_root = Rigid3();
    const HandSearch search(renderer.hand(), renderer.options().intrinsics);
    const std::vector<SearchHypothesis> best = search.Best(
        segmentation.hand_points, rendered.frame,
        {CurledHand(renderer.hand(), 0.0), CurledHand(renderer.hand(), 0.5), articulation}, {}, 3);
    ASSERT_EQ(best.size(), 3u);
    EXPECT_LE(best[0].score, best[1].score);
    EXPECT_LE(best[1].score, best[2].score);
    // The best is the true articulation, placed within a finger's width and 15° of the truth.
    EXPECT_EQ(best[0].pose.angles_rad, truth.angles_rad) << "azimuth " << azimuth;
    const Rigid3 error = best[0].pose.cam_from_root * truth.cam_from_root.Inverse();
    const std::vector<Eigen::Vector3d> found_joints =
        renderer.hand().JointPositions(ForwardKinematics(renderer.hand(), best[0].pose));
    double joint_error = 0;
    for (size_t j = 0; j < found_joints.size(); ++j)
      joint_error += (found_joints[j] - rendered.joints_mm[j]).norm() / found_joints.size();
    const double angle_deg = Eigen::AngleAxisd(error.rotation()).angle() * 180 / M_PI;
    std::printf("azimuth %.0f: score %.2f (next %.2f), joint error %.1f mm, %.1f deg\n", azimuth,
                best[0].score, best[1].score, joint_error, angle_deg);
    EXPECT_LT(joint_error, 15.0) << "azimuth " << azimuth;
    EXPECT_LT(angle_deg, 15.0) << "azimuth " << azimuth;
  }
}

TEST(HandSearchTest, TheSameHypothesesOnOneThreadOrSeveral) {
  // The starts are split among the threads, each run cutting short the scores that cannot be
  // among its best: the hypotheses must not depend on the split (a scan replayed twice gives
  // the same hands).
  const HandModel hand = MakeProceduralHand();
  HandPose truth = CurledHand(hand, 0.4);
  truth.cam_from_root =
      Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, 1, 0.2).normalized(), 2.2, {30, -20, 550});
  const CameraIntrinsics intrinsics;
  Frame frame = Frame::Blank(640, 480, true);
  const std::vector<Eigen::Vector3f> visible = SplatHand(hand, truth, intrinsics, &frame);
  auto search = [&](int threads) {
    HandSearchOptions options;
    options.threads = threads;
    return HandSearch(hand, intrinsics, options)
        .Best(visible, frame, {CurledHand(hand, 0.0), CurledHand(hand, 0.8)}, {}, 12);
  };
  const std::vector<SearchHypothesis> one = search(1);
  ASSERT_EQ(one.size(), 12u);
  for (int threads : {2, 3, 7}) {
    const std::vector<SearchHypothesis> several = search(threads);
    ASSERT_EQ(several.size(), one.size()) << threads << " threads";
    for (size_t k = 0; k < one.size(); ++k) {
      EXPECT_EQ(several[k].score, one[k].score) << threads << " threads, hypothesis " << k;
      EXPECT_EQ(several[k].pose.angles_rad, one[k].pose.angles_rad);
      EXPECT_TRUE(several[k].pose.cam_from_root.ToMatrix() == one[k].pose.cam_from_root.ToMatrix())
          << threads << " threads, hypothesis " << k;
    }
  }
}

TEST(HandSearchTest, PlacesAHandSeenFromOneSideWhereItIs) {
  // A curled procedural hand turned and placed in front of the camera, seen as a z-buffer of
  // its vertices (3×3 pixel splats): the search must find the curl and the place from the
  // visible vertices and that depth image alone.
  // The right curl ranked first and placed within a finger's width (15 mm: the articulated
  // fit, which follows the search, brings it in from there), seen from three sides.
  const HandModel hand = MakeProceduralHand();
  for (const Rigid3& cam_from_root :
       {Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, 1, 0.2).normalized(), 2.2, {30, -20, 550}),
        Rigid3::FromAxisAngle(Eigen::Vector3d(1, 0, 0), -1.2, {-40, 10, 700}),
        Rigid3::FromAxisAngle(Eigen::Vector3d(0.5, -0.5, 1).normalized(), 0.7, {0, 40, 450})}) {
    HandPose truth = CurledHand(hand, 0.4);
    truth.cam_from_root = cam_from_root;
    const CameraIntrinsics intrinsics;
    Frame frame = Frame::Blank(640, 480, true);
    const std::vector<Eigen::Vector3f> vertices =
        hand.Pose(ForwardKinematics(hand, truth)).vertices;
    const std::vector<Eigen::Vector3f> visible = SplatHand(hand, truth, intrinsics, &frame);
    ASSERT_GT(visible.size(), vertices.size() / 10);
    ASSERT_LT(visible.size(), vertices.size() * 4 / 5);
    const HandSearch search(hand, intrinsics);
    const std::vector<SearchHypothesis> best =
        search.Best(visible, frame,
                    {CurledHand(hand, 0.0), CurledHand(hand, 0.4), CurledHand(hand, 0.8)}, {}, 2);
    ASSERT_EQ(best.size(), 2u);
    EXPECT_EQ(best[0].pose.angles_rad, truth.angles_rad);
    const std::vector<Eigen::Vector3d> expected =
        hand.JointPositions(ForwardKinematics(hand, truth));
    auto joint_error = [&](const HandPose& pose) {
      const std::vector<Eigen::Vector3d> found = hand.JointPositions(ForwardKinematics(hand, pose));
      double error = 0;
      for (size_t j = 0; j < found.size(); ++j)
        error += (found[j] - expected[j]).norm() / found.size();
      return error;
    };
    // And the articulated fit, run from there as the tracker's search runs it (two updates
    // and eight more, a loose pull toward the start's angles), brings it in.
    HandFitOptions fit_options;
    fit_options.outer_iterations =
        TrackerOptions().search_coarse_iterations + TrackerOptions().initialisation_iterations;
    fit_options.prior_weight = 0.5;
    const HandFitResult fitted =
        HandFitter(hand, intrinsics, fit_options).Fit(visible, &frame, best[0].pose);
    const double error = joint_error(best[0].pose), fitted_error = joint_error(fitted.pose);
    std::printf("score %.2f (next %.2f), joint error %.2f mm, fitted from there %.2f mm\n",
                best[0].score, best[1].score, error, fitted_error);
    EXPECT_LT(error, 15.0);
    // Measured: placed 6.0 / 7.6 / 14.3 mm off, fitted to 2.2 / 2.3 / 3.1 mm.
    EXPECT_LT(fitted_error, error);
    EXPECT_LT(fitted_error, 5.0);
  }
}

TEST(HandSearchTest, GraspStartsHoldTheObjectInThePalm) {
  // Every start faces the object with its palm, its palm's middle as far from the object as
  // the hand points are, the untilted ones on the line from the object to them; for either hand.
  const Eigen::Vector3d object(10, -20, 600), hand_points(60, 10, 560);
  HandSearchOptions options;
  for (bool right : {true, false}) {
    ProceduralHandOptions side;
    side.right_hand = right;
    const HandModel hand = MakeProceduralHand(side);
    HandPose pose = CurledHand(hand, 0.4);
    const PalmAxes palm = PalmAxesOf(hand, hand.JointPositions(ForwardKinematics(hand, pose)));
    const std::vector<Rigid3> starts = GraspStarts(palm, right, object, hand_points, options);
    ASSERT_EQ(starts.size(), 5u * options.grasp_rolls);
    const double distance = (hand_points - object).norm();
    for (size_t k = 0; k < starts.size(); ++k) {
      pose.cam_from_root = starts[k];
      const PalmAxes placed = PalmAxesOf(hand, hand.JointPositions(ForwardKinematics(hand, pose)));
      const Eigen::Vector3d normal = (right ? 1.0 : -1.0) * placed.Normal().normalized();
      EXPECT_GT(normal.dot((object - placed.centre).normalized()), 1 - 1e-9) << k;
      EXPECT_NEAR((placed.centre - object).norm(), distance, 1e-6) << k;
      if (k < static_cast<size_t>(options.grasp_rolls)) {
        EXPECT_GT((placed.centre - object).normalized().dot((hand_points - object).normalized()),
                  1 - 1e-9);
      }
      // Turned about the normal: consecutive rolls' long axes are one step apart.
      if (k % options.grasp_rolls > 0) {
        pose.cam_from_root = starts[k - 1];
        const PalmAxes previous =
            PalmAxesOf(hand, hand.JointPositions(ForwardKinematics(hand, pose)));
        const double step = std::acos(
            std::clamp(placed.along.normalized().dot(previous.along.normalized()), -1.0, 1.0));
        EXPECT_LT(step, 2 * M_PI / options.grasp_rolls + 0.05) << k;
        EXPECT_GT(step, 0.5 * M_PI / options.grasp_rolls) << k;
      }
    }
  }
  options.grasp_rolls = -1;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

TEST(HandSearchTest, ThumbVariantsMoveOnlyTheThumbsFirstJointAcrossItsRange) {
  const HandModel model = MakeProceduralHand();
  const HandPose pose = CurledHand(model, 0.4);
  const std::vector<HandPose> variants = ThumbVariants(model, pose);
  const std::vector<DegreeOfFreedom> dofs = JointDegreesOfFreedom(model);
  int thumb_base = -1;  // The thumb's first bone with angles: three of them on this template.
  for (const DegreeOfFreedom& dof : dofs)
    if (thumb_base < 0 && model.FingerOf(dof.bone) == 4) thumb_base = dof.bone;
  ASSERT_GE(thumb_base, 0);
  ASSERT_EQ(variants.size(), 27u);
  std::set<std::vector<double>> distinct;
  for (const HandPose& variant : variants) {
    std::vector<double> thumb;
    for (size_t k = 0; k < dofs.size(); ++k) {
      if (dofs[k].bone != thumb_base) {
        EXPECT_EQ(variant.angles_rad[k], pose.angles_rad[k]);
        continue;
      }
      const auto [low, high] = model.limits[thumb_base].limits_deg[dofs[k].axis];
      const double deg = variant.angles_rad[k] * 180 / M_PI;
      EXPECT_GT(deg, low);
      EXPECT_LT(deg, high);
      thumb.push_back(deg);
    }
    distinct.insert(thumb);
    EXPECT_TRUE(variant.cam_from_root.translation().isApprox(pose.cam_from_root.translation()));
  }
  EXPECT_EQ(distinct.size(), 27u);
}

TEST(HandSearchTest, NoPointsGiveNoHypotheses) {
  const HandModel hand = MakeProceduralHand();
  const HandSearch search(hand, CameraIntrinsics());
  EXPECT_TRUE(search.Best({}, Frame::Blank(640, 480, true), {CurledHand(hand, 0)}, {}, 5).empty());
  EXPECT_THROW(HandSearch(hand, CameraIntrinsics(), HandSearchOptions{0, 8, 6, 250, 30.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace ihs::tracker
