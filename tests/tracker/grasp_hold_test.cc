// A grasp held through frames whose detection misses it: the procedural hand in its rest pose,
// thumb and index detected touching object points, then frames where the detection finds
// nothing while the hand keeps its shape, opens, leaves the object or holds too long.
#include "tracker/grasp_hold.h"

#include <gtest/gtest.h>

#include "core/point_kd_tree.h"
#include "tracker/hand_data.h"

namespace ihs::tracker {
namespace {

constexpr int kIndex = 3;
constexpr int kThumb = 4;

class GraspHoldTest : public ::testing::Test {
 protected:
  GraspHoldTest()
      : hand_(LoadHandTemplate("procedural")),
        detector_(hand_),
        mesh_(hand_.rest_mesh),
        cam_from_root_(Rigid3::FromRotationVector({0.3, -0.2, 0.1}, {5, -10, 450})) {
    if (!mesh_.HasNormals()) mesh_.ComputeVertexNormals();
    // The hand placed in the camera: its vertices and object points 0.5 mm outside the thumb's
    // and the index's fingertips.
    for (const Eigen::Vector3f& v : mesh_.vertices)
      vertices_.push_back((cam_from_root_ * Eigen::Vector3d(v.cast<double>())).cast<float>());
    for (int end : {kThumb, kIndex}) {
      for (int v : detector_.fingertip_vertices()[end]) {
        const Eigen::Vector3d normal = cam_from_root_.rotation() * mesh_.normals[v].cast<double>();
        points_.push_back(vertices_[v] + 0.5f * normal.cast<float>());
      }
    }
    object_ = std::make_unique<PointKdTree>(points_);
  }

  // A hold with `options`, switched on.
  GraspHold MakeHold(GraspHoldOptions options = On()) const {
    return GraspHold(options, 2, hand_.EndEffectors(), detector_.fingertip_vertices());
  }

  // `points` moved rigidly by `motion` (camera frame): the hand keeps its shape.
  static std::vector<Eigen::Vector3f> Moved(const std::vector<Eigen::Vector3f>& points,
                                            const Rigid3& motion) {
    std::vector<Eigen::Vector3f> moved;
    for (const Eigen::Vector3f& p : points)
      moved.push_back((motion * Eigen::Vector3d(p.cast<double>())).cast<float>());
    return moved;
  }

  static GraspHoldOptions On() {
    GraspHoldOptions options;
    options.enabled = true;
    return options;
  }

  HandModel hand_;
  ContactDetector detector_;
  TriangleMesh mesh_;
  Rigid3 cam_from_root_;
  std::vector<Eigen::Vector3f> vertices_;
  std::vector<Eigen::Vector3f> points_;  // The object's, near the thumb and the index.
  std::unique_ptr<PointKdTree> object_;
};

TEST_F(GraspHoldTest, AGraspTheDetectionMissesIsHeldWhileTheHandKeepsItsShape) {
  GraspHold hold = MakeHold();
  const Contacts detected = detector_.Detect(vertices_, *object_);
  ASSERT_EQ(detected.bones.size(), 2u);
  EXPECT_EQ(hold.Update(detected, vertices_, cam_from_root_, *object_).held_frames, 0);

  // The hand and the object turn on together by 2° a frame about the hand's root; the
  // detection sees nothing.
  const Eigen::Vector3d root = cam_from_root_.translation();
  for (int frame = 1; frame <= 5; ++frame) {
    const Rigid3 motion = Rigid3::Translation(root + Eigen::Vector3d(frame, 0, 0)) *
                          Rigid3::FromRotationVector({0, 0.035 * frame, 0}, {0, 0, 0}) *
                          Rigid3::Translation(-root);
    const PointKdTree object(Moved(points_, motion));
    const Contacts held =
        hold.Update(Contacts{}, Moved(vertices_, motion), motion * cam_from_root_, object);
    EXPECT_EQ(held.held_frames, frame);
    EXPECT_EQ(held.bones, detected.bones);
    EXPECT_EQ(held.vertices, detected.vertices);
  }
}

TEST_F(GraspHoldTest, AHandThatOpensLetsGo) {
  GraspHold hold = MakeHold();
  hold.Update(detector_.Detect(vertices_, *object_), vertices_, cam_from_root_, *object_);
  // The index fingertip backs off by 8 mm in the hand's frame (a release): not held.
  std::vector<Eigen::Vector3f> opened = vertices_;
  const Eigen::Vector3d back = cam_from_root_.rotation() * Eigen::Vector3d(0, 0, 8);
  for (int v : detector_.fingertip_vertices()[kIndex]) opened[v] += back.cast<float>();
  EXPECT_TRUE(hold.Update(Contacts{}, opened, cam_from_root_, *object_).bones.empty());
  // Nor once the shape is back: the grasp was let go and must be detected anew.
  EXPECT_TRUE(hold.Update(Contacts{}, vertices_, cam_from_root_, *object_).bones.empty());
}

TEST_F(GraspHoldTest, AHandAwayFromTheObjectOrHoldingTooLongLetsGo) {
  GraspHoldOptions options = On();
  options.max_frames = 3;
  GraspHold hold = MakeHold(options);
  const Contacts detected = detector_.Detect(vertices_, *object_);
  hold.Update(detected, vertices_, cam_from_root_, *object_);
  for (int frame = 1; frame <= 3; ++frame)
    EXPECT_EQ(hold.Update(Contacts{}, vertices_, cam_from_root_, *object_).held_frames, frame);
  EXPECT_TRUE(hold.Update(Contacts{}, vertices_, cam_from_root_, *object_).bones.empty());

  // Detected again, then the whole hand 40 mm away from the object's points: let go.
  hold.Update(detected, vertices_, cam_from_root_, *object_);
  const Rigid3 away = Rigid3::Translation({40, 0, 0});
  EXPECT_TRUE(hold.Update(Contacts{}, Moved(vertices_, away), away * cam_from_root_, *object_)
                  .bones.empty());
}

TEST_F(GraspHoldTest, OffItPassesTheDetectionOn) {
  GraspHoldOptions options;
  options.enabled = false;
  GraspHold hold = MakeHold(options);
  hold.Update(detector_.Detect(vertices_, *object_), vertices_, cam_from_root_, *object_);
  EXPECT_TRUE(hold.Update(Contacts{}, vertices_, cam_from_root_, *object_).bones.empty());
  options.max_shape_change_mm = 0;
  EXPECT_THROW(MakeHold(options), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::tracker
