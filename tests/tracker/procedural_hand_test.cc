#include "tracker/procedural_hand.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/offscreen_renderer.h"
#include "tests/test_util.h"
#include "tracker/hand_data.h"
#include "tracker/hand_pose.h"

namespace ihs::tracker {
namespace {

TEST(ProceduralHandTest, HasTheRealModelsTopologyAndAClosedMesh) {
  const HandModel hand = MakeProceduralHand();
  ASSERT_EQ(hand.bones.size(), 20u);
  EXPECT_EQ(hand.bones[0].name, "Lower Arm R");
  for (const char* name : {"RFing.0_2", "RFing.3_Hand", "RFing.4_1"}) {
    EXPECT_GE(hand.BoneIndex(name), 0) << name;
  }
  std::vector<std::string> ends;
  for (int end : hand.EndEffectors()) ends.push_back(hand.bones[end].name);
  EXPECT_EQ(ends, (std::vector<std::string>{"RFing.0_2", "RFing.1_2", "RFing.2_2", "RFing.3_2",
                                            "RFing.4_1"}));
  EXPECT_EQ(JointDegreesOfFreedom(hand).size(), 26u);
  EXPECT_GT(hand.rest_mesh.vertices.size(), 2000u);
  EXPECT_LT(hand.rest_mesh.vertices.size(), 8000u);
  EXPECT_TRUE(hand.rest_mesh.IsWatertight());
  EXPECT_GT(hand.rest_mesh.Volume(), 1e5);  // Outward faces; an adult hand is ~400 cm³.
  const auto [lo, hi] = hand.rest_mesh.Bounds();
  EXPECT_NEAR(hi.z() - lo.z(), 17.6 + 76 + 38 + 26 + 22, 40);  // Wrist to middle fingertip.
}

TEST(ProceduralHandTest, ScalingScalesBonesMeshAndPosedJointsAboutTheWrist) {
  const HandModel hand = MakeProceduralHand();
  const HandModel big = hand.Scaled(1.1);
  EXPECT_NO_THROW(big.Check());
  for (size_t b = 0; b < hand.bones.size(); ++b)
    EXPECT_NEAR(big.bones[b].length_mm, 1.1 * hand.bones[b].length_mm, 1e-9);
  for (size_t v = 0; v < hand.rest_mesh.vertices.size(); v += 97) {
    EXPECT_LT((big.rest_mesh.vertices[v] - 1.1f * hand.rest_mesh.vertices[v]).norm(), 1e-4f);
  }
  // The same angles at the same root placement: every joint 1.1 times as far from the root.
  HandPose pose = HandPose::Rest(hand, Rigid3::FromAxisAngle({1, 2, 0}, 0.5, {5, -10, 600}));
  for (size_t k = 0; k < pose.angles_rad.size(); ++k) pose.angles_rad[k] = -0.2 - 0.01 * k;
  HandPose big_pose = pose;
  big_pose.cam_from_root = Rigid3(pose.cam_from_root.rotation(), pose.cam_from_root.translation());
  const auto joints = hand.JointPositions(ForwardKinematics(hand, pose));
  const auto big_joints = big.JointPositions(ForwardKinematics(big, big_pose));
  const Eigen::Vector3d root = pose.cam_from_root.translation();
  for (size_t j = 0; j < joints.size(); ++j)
    EXPECT_LT((big_joints[j] - root - 1.1 * (joints[j] - root)).norm(), 1e-6) << j;
  EXPECT_THROW(hand.Scaled(0.0), std::invalid_argument);
}

TEST(ProceduralHandTest, FlexionBendsFingersTowardThePalmAndKeepsTheSurface) {
  const HandModel hand = MakeProceduralHand();
  const auto dofs = JointDegreesOfFreedom(hand);
  HandPose pose = HandPose::Rest(hand);
  for (size_t k = 0; k < dofs.size(); ++k) {
    if (dofs[k].axis == 1) pose.angles_rad[k] = -0.6;  // Flex every joint by 34°.
  }
  const auto bones = ForwardKinematics(hand, pose);
  const auto rest_joints = hand.JointPositions(ForwardKinematics(hand, HandPose::Rest(hand)));
  const auto joints = hand.JointPositions(bones);
  for (int end : hand.EndEffectors()) {
    EXPECT_LT(joints[end + 1].y() - rest_joints[end + 1].y(), -20) << hand.bones[end].name;
  }
  const TriangleMesh posed = hand.Pose(bones);
  std::vector<double> stretch;
  for (const auto& face : posed.faces) {
    const double a = (hand.rest_mesh.vertices[face[0]] - hand.rest_mesh.vertices[face[1]]).norm();
    const double b = (posed.vertices[face[0]] - posed.vertices[face[1]]).norm();
    stretch.push_back(std::abs(b - a) / a);
  }
  std::sort(stretch.begin(), stretch.end());
  EXPECT_LT(stretch[stretch.size() / 2], 0.01);
}

TEST(ProceduralHandTest, IsARightHandLikeTheScannedOne) {
  // The paper's data are of a right hand; a mirrored template cannot fit them (its fingers
  // would have to bend backwards).
  EXPECT_TRUE(IsRightHand(MakeProceduralHand()));
  // Its mirror image as far as the kinematics go: fingers that flex toward the back.
  HandModel mirrored = MakeProceduralHand();
  for (JointLimits& limits : mirrored.limits) limits.axes[1] = -limits.axes[1];
  EXPECT_FALSE(IsRightHand(mirrored));
  const auto data = test::HandDataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent: the scanned hand not compared";
  EXPECT_TRUE(IsRightHand(LoadHandModel(data)));
}

TEST(ProceduralHandTest, ALeftHandIsTheRightOnesMirrorImage) {
  ProceduralHandOptions options;
  options.right_hand = false;
  const HandModel left = MakeProceduralHand(options);
  const HandModel right = MakeProceduralHand();
  EXPECT_FALSE(IsRightHand(left));
  EXPECT_TRUE(left.rest_mesh.IsWatertight());
  EXPECT_NEAR(left.rest_mesh.Volume(), right.rest_mesh.Volume(), 1e-3 * right.rest_mesh.Volume());
  const Eigen::Vector3d mirror(1, -1, 1);
  // Every skin vertex of the left hand mirrors onto one of the right hand's.
  ASSERT_EQ(left.rest_mesh.vertices.size(), right.rest_mesh.vertices.size());
  double farthest = 0;
  for (const Eigen::Vector3f& vertex : left.rest_mesh.vertices) {
    const Eigen::Vector3f mirrored = vertex.cwiseProduct(mirror.cast<float>());
    float nearest = std::numeric_limits<float>::infinity();
    for (const Eigen::Vector3f& other : right.rest_mesh.vertices)
      nearest = std::min(nearest, (other - mirrored).squaredNorm());
    farthest = std::max(farthest, static_cast<double>(std::sqrt(nearest)));
  }
  EXPECT_LT(farthest, 1e-3);
  // The same flexion, with twist and spread the other way round, poses the mirror image.
  const auto dofs = JointDegreesOfFreedom(right);
  HandPose right_pose = HandPose::Rest(right), left_pose = HandPose::Rest(left);
  for (size_t k = 0; k < dofs.size(); ++k) {
    right_pose.angles_rad[k] = dofs[k].axis == 1 ? -0.5 : 0.15;
    left_pose.angles_rad[k] = dofs[k].axis == 1 ? -0.5 : -0.15;
  }
  const auto right_joints = right.JointPositions(ForwardKinematics(right, right_pose));
  const auto left_joints = left.JointPositions(ForwardKinematics(left, left_pose));
  for (size_t j = 0; j < right_joints.size(); ++j)
    EXPECT_LT((left_joints[j] - right_joints[j].cwiseProduct(mirror)).norm(), 1e-9) << j;
}

// Whether `point` lies inside the closed `mesh`, a union of overlapping closed surfaces: a ray
// from it leaves the surfaces more often than it enters them (outward faces).
bool Inside(const TriangleMesh& mesh, const Eigen::Vector3d& point) {
  const Eigen::Vector3d ray = Eigen::Vector3d(0.31, 0.52, 0.8).normalized();
  int exits = 0;
  for (const auto& face : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[face[0]].cast<double>();
    const Eigen::Vector3d e1 = mesh.vertices[face[1]].cast<double>() - a;
    const Eigen::Vector3d e2 = mesh.vertices[face[2]].cast<double>() - a;
    const Eigen::Vector3d p = ray.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-12) continue;
    const Eigen::Vector3d s = point - a;
    const double u = s.dot(p) / det, v = ray.dot(s.cross(e1)) / det;
    if (u < 0 || v < 0 || u + v > 1) continue;
    if (e2.dot(s.cross(e1)) / det > 0) exits += det < 0 ? 1 : -1;  // det < 0: leaving.
  }
  return exits > 0;
}

// The scanned hand's wrist and knuckle places (ProceduralHandOptions' comment), its skin toward
// the palm from the bones.
ProceduralHandOptions ScannedLayout() {
  ProceduralHandOptions options;
  options.wrist_start_mm = {0.3, -5.7, -16.6};
  options.metacarpal_start_mm = {
      {{-10.4, -3.1, -4.4}, {-5.6, -0.7, -1.8}, {0, 0, 0}, {6.0, -0.5, -0.4}}};
  options.metacarpal_end_mm = {
      {{-42.8, -3.4, 57.9}, {-24.9, 11.3, 67.1}, {-6.0, 15.6, 73.0}, {15.7, 14.9, 73.7}}};
  options.palm_thickness_mm = 32;
  options.wrist_thickness_mm = 44;
  options.wrist_palmar_offset_mm = 11;
  options.palm_palmar_offset_mm = 9;
  options.finger_palmar_offset = 0.35;
  return options;
}

TEST(ProceduralHandTest, EveryBoneRunsInsideTheSkin) {
  for (int variant = 0; variant < 4; ++variant) {
    const bool right = variant % 2 == 0;
    ProceduralHandOptions options = variant < 2 ? ProceduralHandOptions() : ScannedLayout();
    options.right_hand = right;
    const HandModel hand = MakeProceduralHand(options);
    EXPECT_EQ(IsRightHand(hand), right);
    const auto joints = hand.JointPositions(ForwardKinematics(hand, HandPose::Rest(hand)));
    for (size_t b = 0; b < hand.bones.size(); ++b) {
      // Joint b + 1 is bone b's end; a finger bone starts at its parent's end, the metacarpals
      // and the root at the places the model gives.
      const Eigen::Vector3d start = hand.model_from_bone_rest[b].translation();
      for (double t : {0.1, 0.5, 0.9}) {
        const Eigen::Vector3d point = start + t * (joints[b + 1] - start);
        EXPECT_TRUE(Inside(hand.rest_mesh, point)) << hand.bones[b].name << " at " << t;
      }
    }
  }
}

TEST(ProceduralHandTest, PlacesItsWristAndKnucklesWhereTheOptionsSay) {
  const HandModel hand = MakeProceduralHand(ScannedLayout());
  EXPECT_TRUE(hand.rest_mesh.IsWatertight());
  const auto joints = hand.JointPositions(ForwardKinematics(hand, HandPose::Rest(hand)));
  // Joint 1 is the wrist joint (the origin of the options' places), 2, 6, 10, 14 the knuckles.
  EXPECT_LT(joints[1].norm(), 1e-9);
  EXPECT_LT((joints[0] - Eigen::Vector3d(0.3, -5.7, -16.6)).norm(), 1e-9);
  EXPECT_LT((joints[2] - Eigen::Vector3d(-42.8, -3.4, 57.9)).norm(), 1e-9);
  EXPECT_LT((joints[14] - Eigen::Vector3d(15.7, 14.9, 73.7)).norm(), 1e-9);
  // The wrist's skin (the vertices on the root bone alone) has its middle 11 mm into the palm
  // from the bone (BoneFrame's z); the default's on the bone.
  for (const auto& [options, palmar] : {std::pair{ScannedLayout(), 11.0}, {{}, 0.0}}) {
    const HandModel model = MakeProceduralHand(options);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (size_t v = 0; v < model.rest_mesh.vertices.size(); ++v) {
      const auto& bones = model.weights[v].bones;
      if (bones.size() != 1 || bones[0].first != 0) continue;
      sum += model.rest_mesh.vertices[v].cast<double>();
      ++count;
    }
    ASSERT_GT(count, 100);
    const Rigid3& wrist = model.model_from_bone_rest[0];
    EXPECT_NEAR((sum / count - wrist.translation()).dot(wrist.rotation().col(2)), palmar, 0.01);
  }
  // Where the scanned hand is at hand, its rest joints: the same places.
  const auto data = test::HandDataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent: the scanned hand not compared";
  const HandModel scanned = LoadHandModel(data);
  const auto truth = scanned.JointPositions(ForwardKinematics(scanned, HandPose::Rest(scanned)));
  for (int j : {0, 2, 6, 10, 14}) {
    EXPECT_LT(((joints[j] - joints[1]) - (truth[j] - truth[1])).norm(), 0.2) << "joint " << j;
  }
  EXPECT_THROW(
      [] {
        ProceduralHandOptions bad;
        bad.finger_palmar_offset = 1.5;
        MakeProceduralHand(bad);
      }(),
      std::invalid_argument);
}

TEST(ProceduralHandTest, RendersAsAHandSizedBlobInFrontOfTheCamera) {
  const HandModel hand = MakeProceduralHand();
  render::OffscreenRenderer renderer(CameraIntrinsics{});
  render::RenderItem item{&hand.rest_mesh,
                          Rigid3::FromAxisAngle({1, 0, 0}, M_PI / 2, {0, 0, 600}),
                          {220, 170, 140},
                          false,
                          render::kHand};
  const render::RenderOutput out = renderer.Render({item});
  const long hand_pixels = std::count(out.labels.begin(), out.labels.end(), render::kHand);
  // Palm toward the camera at 60 cm: roughly 90 × 180 mm → ~12 000 px at f = 525.
  EXPECT_GT(hand_pixels, 6000);
  EXPECT_LT(hand_pixels, 25000);
}

}  // namespace
}  // namespace ihs::tracker
