#include "tracker/hand_joints_io.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"
#include "tracker/hand_pose.h"
#include "tracker/hand_search.h"
#include "tracker/procedural_hand.h"

namespace ihs::tracker {
namespace {

TEST(HandJointsIoTest, AHandTurnedOverIsToldFromTheTruthAndTurnsBack) {
  const HandModel hand = MakeProceduralHand();
  HandPose pose = CurledHand(hand, 0.3);
  pose.cam_from_root = Rigid3::FromAxisAngle({0.3, 1, 0.2}, 0.8, {10, -20, 550});
  auto joints = [&](const HandPose& p) { return hand.JointPositions(ForwardKinematics(hand, p)); };
  const std::vector<Eigen::Vector3d> truth = joints(pose);
  EXPECT_FALSE(CompareHandSides(hand, truth, truth).turned_over());
  // A few millimetres and degrees off is not turned over.
  HandPose near = pose;
  near.cam_from_root = Rigid3::FromAxisAngle({1, 0, 0}, 0.2, {4, 3, 0}) * pose.cam_from_root;
  EXPECT_FALSE(CompareHandSides(hand, joints(near), truth).turned_over());
  const HandPose turned = TurnedOver(hand, pose);
  const std::vector<Eigen::Vector3d> over = joints(turned);
  // Palm for back, and the thumb's tip over on the little finger's side.
  EXPECT_TRUE(CompareHandSides(hand, over, truth).palm_reversed);
  EXPECT_TRUE(CompareHandSides(hand, over, truth).thumb_swapped);
  // Only the thumb swung over to the little finger: not palm for back.
  std::vector<Eigen::Vector3d> thumb_over = truth;
  const int thumb = hand.BoneIndex("RFing.4_1") + 1, little = hand.BoneIndex("RFing.0_2") + 1;
  thumb_over[thumb] = truth[little] + Eigen::Vector3d(5, 0, 0);
  EXPECT_TRUE(CompareHandSides(hand, thumb_over, truth).thumb_swapped);
  EXPECT_FALSE(CompareHandSides(hand, thumb_over, truth).palm_reversed);
  // Turned over twice is where it was.
  const std::vector<Eigen::Vector3d> back = joints(TurnedOver(hand, turned));
  for (size_t j = 0; j < truth.size(); ++j) EXPECT_LT((back[j] - truth[j]).norm(), 1e-6) << j;
  EXPECT_THROW(CompareHandSides(hand, {truth.begin(), truth.end() - 1}, truth),
               std::invalid_argument);
}

TEST(HandJointsIoTest, RoundTripsTheJointsOfAPosedHandToATenthOfAMicrometre) {
  const HandModel hand = MakeProceduralHand();
  std::vector<std::string> names;
  for (const Bone& bone : hand.bones) names.push_back(bone.name);
  std::vector<HandJointsRow> rows;
  for (int frame = 0; frame < 5; ++frame) {
    const HandPose pose =
        HandPose::Rest(hand, Rigid3::FromAxisAngle({0, 1, 0}, 0.2 * frame, {0, 0, 600}));
    rows.push_back({frame, hand.JointPositions(ForwardKinematics(hand, pose))});
  }
  test::TempDir dir;
  WriteHandJointsCsv(dir / "hand_joints.csv", names, rows);
  const std::string text = test::ReadFileString(dir / "hand_joints.csv");
  EXPECT_EQ(text.rfind("frame,Lower_Arm_R_start_x,Lower_Arm_R_start_y,", 0), 0u)
      << text.substr(0, 80);
  const auto read = ReadHandJointsCsv(dir / "hand_joints.csv");
  ASSERT_EQ(read.size(), 5u);
  for (size_t f = 0; f < read.size(); ++f) {
    EXPECT_EQ(read[f].frame, rows[f].frame);
    ASSERT_EQ(read[f].joints_mm.size(), 21u);
    for (size_t j = 0; j < 21; ++j) {
      EXPECT_LT((read[f].joints_mm[j] - rows[f].joints_mm[j]).norm(), 1e-4);
    }
  }
  EXPECT_THROW(WriteHandJointsCsv(dir / "x.csv", names, {{0, {Eigen::Vector3d::Zero()}}}),
               std::invalid_argument);
}

TEST(HandJointsIoTest, MeanJointErrorIsTheMeanDistanceOfCorrespondingJoints) {
  const std::vector<Eigen::Vector3d> truth = {{0, 0, 600}, {10, 0, 600}, {0, 10, 600}};
  std::vector<Eigen::Vector3d> estimate = truth;
  EXPECT_DOUBLE_EQ(MeanJointError(estimate, truth), 0.0);
  estimate[0].x() += 3;                     // 3 mm
  estimate[2].z() -= 4;                     // 4 mm
  estimate[1] += Eigen::Vector3d(0, 3, 4);  // 5 mm
  EXPECT_DOUBLE_EQ(MeanJointError(estimate, truth), 4.0);
  estimate.pop_back();
  EXPECT_THROW(MeanJointError(estimate, truth), std::invalid_argument);
  EXPECT_THROW(MeanJointError({}, {}), std::invalid_argument);
}

TEST(HandJointsIoTest, MalformedFilesAreInputErrors) {
  test::TempDir dir;
  for (const char* bytes :
       {"", "x,y,z\n", "frame,a_x,a_y,a_z\n1,2,3\n", "frame,a_x,a_y,a_z\n1,2,three,4\n"}) {
    test::WriteBytes(dir / "bad.csv", bytes);
    EXPECT_THROW(ReadHandJointsCsv(dir / "bad.csv"), InputError) << bytes;
  }
}

}  // namespace
}  // namespace ihs::tracker
