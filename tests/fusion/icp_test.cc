// ICP against a raycast of the model: an ellipsoid (no symmetry to slide along) fused from views
// all around, then a new view whose predicted pose is off by 5 mm and 5°; a sphere, whose turns
// the surface leaves free.

#include "fusion/icp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tests/frame_fixtures.h"

namespace ihs::fusion {
namespace {

const Eigen::Vector3d kSemiAxes(45, 30, 18);

// The largest distance between where two poses put the ellipsoid's extreme points.
double PoseError(const Rigid3& a, const Rigid3& b) {
  double worst = 0;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p[axis] = sign * kSemiAxes[axis];
      worst = std::max(worst, (a * p - b * p).norm());
    }
  }
  return worst;
}

class IcpTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    volume_ = new TsdfVolume();
    for (int a = 0; a < 8; ++a) {
      for (double tilt : {-0.9, 0.0, 0.9}) {
        const Rigid3 view = Rigid3::Translation({0, 0, 600}) *
                            Rigid3::FromAxisAngle({1, 0, 0}, tilt) *
                            Rigid3::FromAxisAngle({0, 1, 0}, a * M_PI / 4);
        volume_->Integrate(test::RenderEllipsoid(intrinsics_, view, kSemiAxes), {}, intrinsics_,
                           view);
      }
    }
  }
  static void TearDownTestSuite() { delete volume_; }

  // The object points of a frame (camera frame).
  static std::vector<Eigen::Vector3f> Points(const Frame& frame) {
    std::vector<Eigen::Vector3f> points;
    for (int v = 0; v < frame.height; ++v) {
      for (int u = 0; u < frame.width; ++u) {
        const std::uint16_t z = frame.DepthAt(u, v);
        if (z != 0) points.push_back(intrinsics_.BackProject(u, v, z).cast<float>());
      }
    }
    return points;
  }

  static inline TsdfVolume* volume_ = nullptr;
  static inline const CameraIntrinsics intrinsics_ = CameraIntrinsics::Carmine109();
};

TEST_F(IcpTest, ConvergesFromFiveMillimetresAndFiveDegreesOff) {
  const Rigid3 truth =
      Rigid3::Translation({8, -6, 590}) * Rigid3::FromAxisAngle(Eigen::Vector3d(0.4, 1, -0.3), 0.6);
  const std::vector<Eigen::Vector3f> points =
      Points(test::RenderEllipsoid(intrinsics_, truth, kSemiAxes));
  for (const Eigen::Vector3d& axis :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(1, -1, 0.5)}) {
    // Off by 5 mm and 5° about the object's centre.
    const Rigid3 offset =
        Rigid3::Translation(truth.translation() + 5.0 * axis.normalized()) *
        Rigid3::FromAxisAngle(axis.cross(Eigen::Vector3d(0.3, 0.2, 1)), 5 * M_PI / 180) *
        Rigid3::Translation(-truth.translation());
    const Rigid3 predicted = offset * truth;
    const RaycastImage model = volume_->Raycast(intrinsics_, predicted);
    const IcpResult result = AlignToModel(points, model, intrinsics_, predicted);
    std::printf("off %.1f mm -> %.3f mm after %d iterations, %d of %zu pairs, rms %.2f mm\n",
                PoseError(predicted, truth), PoseError(result.cam_from_volume, truth),
                result.iterations, result.inliers, points.size(), result.rms_mm);
    ASSERT_TRUE(result.ok) << result.reason;
    // Measured: 7–8 mm off -> 0.43–0.45 mm. Started at the truth itself ICP settles 0.34 mm
    // away: the model, fused from whole-millimetre depths into 1.37 mm voxels, is that good.
    EXPECT_LT(PoseError(result.cam_from_volume, truth), 0.6);
    EXPECT_LT(result.rms_mm, 1.0);
  }
}

TEST_F(IcpTest, AnchorsForTheFreeDirectionsOnlyLeaveAFullyFixedSurfaceAlone) {
  // The ellipsoid's surface fixes every direction: anchors meant only for what it leaves free
  // change nothing, even anchors 3 mm off (a mistracked fingertip); anchors solved with the
  // surface pull the pose toward them.
  const Rigid3 truth =
      Rigid3::Translation({8, -6, 590}) * Rigid3::FromAxisAngle(Eigen::Vector3d(0.4, 1, -0.3), 0.6);
  const std::vector<Eigen::Vector3f> points =
      Points(test::RenderEllipsoid(intrinsics_, truth, kSemiAxes));
  const Rigid3 predicted = Rigid3::Translation({3, 2, -2}) * truth;
  const RaycastImage model = volume_->Raycast(intrinsics_, predicted);
  std::vector<IcpAnchor> anchors;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d q(kSemiAxes.x(), 4 * std::cos(k), 4 * std::sin(k));
    anchors.push_back({truth * q + Eigen::Vector3d(0, 3, 0), predicted * q, 1.0});
  }
  IcpOptions options;
  options.anchor_share = 0.2;
  const IcpResult alone = AlignToModel(points, model, intrinsics_, predicted, options);
  const IcpResult joint = AlignToModel(points, model, intrinsics_, predicted, options, anchors);
  options.anchors_free_directions_only = true;
  const IcpResult free = AlignToModel(points, model, intrinsics_, predicted, options, anchors);
  std::printf(
      "ellipsoid, anchors 3 mm off: %.3f mm from the truth alone, %.3f free only, %.3f "
      "joint\n",
      PoseError(alone.cam_from_volume, truth), PoseError(free.cam_from_volume, truth),
      PoseError(joint.cam_from_volume, truth));
  ASSERT_TRUE(alone.ok && free.ok && joint.ok);
  EXPECT_LT(PoseError(free.cam_from_volume, alone.cam_from_volume), 0.01);
  EXPECT_GT(PoseError(joint.cam_from_volume, alone.cam_from_volume), 0.1);
}

TEST_F(IcpTest, TooFewPairsIsNotTrusted) {
  const Rigid3 truth = Rigid3::Translation({0, 0, 600});
  const RaycastImage model = volume_->Raycast(intrinsics_, truth);
  // The object 120 mm away from where the model is predicted (beyond its 45 mm semi-axis twice):
  // nothing pairs within 5 mm. (At 60 mm the two overlap, and ICP, moving only in the
  // directions the few overlapping pairs constrain, slides towards the object.)
  const std::vector<Eigen::Vector3f> far =
      Points(test::RenderEllipsoid(intrinsics_, Rigid3::Translation({120, 0, 600}), kSemiAxes));
  const IcpResult result = AlignToModel(far, model, intrinsics_, truth);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.reason.find("pair with the model"), std::string::npos) << result.reason;
  IcpOptions bad;
  bad.max_distance_mm = 0;
  EXPECT_THROW(AlignToModel(far, model, intrinsics_, truth, bad), std::invalid_argument);
}

// A flat face 60 mm square, 600 mm in front of the camera, as the model's raycast sees it, and
// the frame's points on it.
struct FlatFace {
  RaycastImage model;
  std::vector<Eigen::Vector3f> points;
};

FlatFace MakeFlatFace(const CameraIntrinsics& intrinsics) {
  FlatFace face;
  face.model.width = intrinsics.width, face.model.height = intrinsics.height;
  const size_t pixels = static_cast<size_t>(intrinsics.width) * intrinsics.height;
  face.model.depth_mm.assign(pixels, 0.0f);
  face.model.normals.assign(pixels, Eigen::Vector3f::Zero());
  face.model.colors.assign(pixels, {0, 0, 0});
  face.model.written = {0, 0, intrinsics.width, intrinsics.height};
  for (int v = 0; v < intrinsics.height; ++v) {
    for (int u = 0; u < intrinsics.width; ++u) {
      const Eigen::Vector3d p = intrinsics.BackProject(u, v, 600);
      if (std::abs(p.x()) > 30 || std::abs(p.y()) > 30) continue;
      face.model.depth_mm[static_cast<size_t>(v) * intrinsics.width + u] = 600;
      face.model.normals[static_cast<size_t>(v) * intrinsics.width + u] = {0, 0, -1};
      face.points.push_back(p.cast<float>());
    }
  }
  return face;
}

TEST(IcpSlideTest, AnIcpThatSlidesOffWhatItStartedOnKeepsItsBestPairedIterate) {
  // A flat face cannot resist a shift along itself: anchors 35 mm off along it (a contact on
  // the wrong finger) drag ICP off the face, which keeps fewer and fewer pairs. With the guard
  // (IcpOptions::min_kept_pair_fraction) the iterate that paired the most is kept.
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  const FlatFace face = MakeFlatFace(intrinsics);
  std::vector<IcpAnchor> anchors;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d p(10 * std::cos(k), 10 * std::sin(k), 600);
    anchors.push_back({p, p + Eigen::Vector3d(35, 0, 0), 1.0});
  }
  IcpOptions off;
  off.min_kept_pair_fraction = 0;
  const Rigid3 predicted;
  const IcpResult slid = AlignToModel(face.points, face.model, intrinsics, predicted, off, anchors);
  const IcpResult kept =
      AlignToModel(face.points, face.model, intrinsics, predicted, IcpOptions(), anchors);
  std::printf(
      "dragged 35 mm along a face: %.1f mm and %d of %d pairs without the guard, %.1f mm "
      "and %d with it\n",
      slid.cam_from_volume.translation().norm(), slid.inliers, slid.first_inliers,
      kept.cam_from_volume.translation().norm(), kept.inliers);
  ASSERT_EQ(slid.points, static_cast<int>(face.points.size()));
  EXPECT_EQ(slid.first_inliers, slid.points);
  // Unguarded, ICP follows the anchors off the face and still calls that a fit.
  EXPECT_TRUE(slid.ok) << slid.reason;
  EXPECT_FALSE(slid.slid);
  EXPECT_GT(slid.cam_from_volume.translation().norm(), 20);
  EXPECT_LT(slid.inliers, 0.5 * slid.first_inliers);
  // Guarded, it stays on the face with every pair.
  EXPECT_TRUE(kept.ok) << kept.reason;
  EXPECT_TRUE(kept.slid);
  EXPECT_LT(kept.cam_from_volume.translation().norm(), 0.01);
  EXPECT_EQ(kept.inliers, kept.first_inliers);
  // Where nothing drags it, the guard has nothing to do.
  const IcpResult still = AlignToModel(face.points, face.model, intrinsics, predicted);
  EXPECT_FALSE(still.slid);
  EXPECT_EQ(still.inliers, still.points);
  IcpOptions bad;
  bad.min_kept_pair_fraction = 1.5;
  EXPECT_THROW(AlignToModel(face.points, face.model, intrinsics, predicted, bad),
               std::invalid_argument);
}

// Depth noise as a Carmine's at 0.6 m (1.5 mm standard deviation, whole millimetres).
Frame Noisy(Frame frame, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, 1.5);
  for (std::uint16_t& depth : frame.depth_mm) {
    if (depth != 0) depth = static_cast<std::uint16_t>(std::lround(depth + noise(rng)));
  }
  return frame;
}

// A ball (60 mm radius) fused from noisy views all around, and a new noisy view of it.
struct Ball {
  static constexpr double kRadius = 60;
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  TsdfVolume volume;
  Rigid3 truth = Rigid3::Translation({5, -3, 580});
  Frame frame;
  std::vector<Eigen::Vector3f> points;

  Ball() {
    const Eigen::Vector3d radii = Eigen::Vector3d::Constant(kRadius);
    std::mt19937 rng(3);
    for (int a = 0; a < 8; ++a) {
      for (double tilt : {-0.9, 0.0, 0.9}) {
        const Rigid3 view = Rigid3::Translation({0, 0, 600}) *
                            Rigid3::FromAxisAngle({1, 0, 0}, tilt) *
                            Rigid3::FromAxisAngle({0, 1, 0}, a * M_PI / 4);
        volume.Integrate(Noisy(test::RenderEllipsoid(intrinsics, view, radii), rng), {}, intrinsics,
                         view);
      }
    }
    frame = Noisy(test::RenderEllipsoid(intrinsics, truth, radii), rng);
    for (int v = 0; v < frame.height; ++v) {
      for (int u = 0; u < frame.width; ++u) {
        const std::uint16_t z = frame.DepthAt(u, v);
        if (z != 0) points.push_back(intrinsics.BackProject(u, v, z).cast<float>());
      }
    }
  }
};

// The angle between two poses' rotations, degrees.
double TurnBetween(const Rigid3& a, const Rigid3& b) {
  return Eigen::AngleAxisd(a.rotation() * b.rotation().transpose()).angle() * 180 / M_PI;
}

TEST(IcpSphereTest, TurnsTheSurfaceLeavesFreeKeepThePrediction) {
  // The new view's prediction is turned by 10° about the centre (the same surface) and shifted
  // by 4 mm (which the surface fixes).
  const Ball ball;
  const CameraIntrinsics& intrinsics = ball.intrinsics;
  const TsdfVolume& volume = ball.volume;
  const Rigid3& truth = ball.truth;
  const Frame& frame = ball.frame;
  const std::vector<Eigen::Vector3f>& points = ball.points;
  const Eigen::Vector3d radii = Eigen::Vector3d::Constant(Ball::kRadius);
  const Rigid3 turned =
      truth * Rigid3::FromAxisAngle(Eigen::Vector3d(0.2, 1, 0.4), 10 * M_PI / 180);
  const Rigid3 predicted = Rigid3::Translation({4, 0, 0}) * turned;
  for (const double ratio : {0.0, IcpOptions().min_constraint_over_noise}) {
    IcpOptions options;
    options.min_constraint_over_noise = ratio;
    const IcpResult result =
        AlignToModel(points, volume.Raycast(intrinsics, predicted), intrinsics, predicted, options);
    ASSERT_TRUE(result.ok) << result.reason;
    const double shift = (result.cam_from_volume.translation() - truth.translation()).norm();
    const double turn = TurnBetween(result.cam_from_volume, turned);
    std::printf(
        "min_constraint_over_noise %g: centre %.3f mm off, turned %.3f° from the prediction\n",
        ratio, shift, turn);
    // Measured: the centre 0.04 mm off either way; solving every direction turns the sphere by
    // 3.7° (the model's flaws decide), keeping the free ones turns it by 0.02°.
    EXPECT_LT(shift, 0.3);
    if (ratio > 0) {
      EXPECT_EQ(result.free_directions, 3) << "a ball's three turns";
      EXPECT_LT(turn, 0.2);
    } else {
      EXPECT_GT(turn, 1.0) << "the free turns were not free: the test shows nothing";
      EXPECT_EQ(result.free_directions, -1) << "not judged with the rule off";
    }
  }

  // One fingertip's patch (six points 5 mm round one point of the ball) where the truth has it,
  // anchoring the free directions only: the ball's turn follows it to the truth, and the
  // centre stays where the surface puts it.
  std::vector<IcpAnchor> anchors;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d direction(radii.x(), 5 * std::cos(k), 5 * std::sin(k));
    const Eigen::Vector3d q = direction.normalized() * radii.x();
    anchors.push_back({truth * q, predicted * q, 1.0});
  }
  // Anchors in every direction (contacts spread across fingertips): the free directions are
  // still judged, aside, for the colour alignment after ICP (colour_align.h).
  const IcpResult joined = AlignToModel(points, volume.Raycast(intrinsics, predicted), intrinsics,
                                        predicted, IcpOptions(), anchors);
  EXPECT_EQ(joined.free_directions, -1) << "the anchors joined every direction";
  EXPECT_EQ(joined.free.size(), 3u) << "a ball's three turns, judged aside";
  for (const FreeDirection& free : joined.free) {
    // A turn about the ball's centre moves no point of its surface off it.
    const Eigen::Vector3d centre = predicted.translation();
    const Eigen::Vector3d on = centre + Eigen::Vector3d(0, 0, -radii.x());
    const Eigen::Vector3d moved = free.turn.cross(on - joined.free_centre) + free.shift;
    EXPECT_LT(std::abs(moved.dot((on - centre).normalized())), 0.05 * moved.norm() + 1e-6);
  }
  IcpOptions options;
  options.anchors_free_directions_only = true;
  const IcpResult result = AlignToModel(points, volume.Raycast(intrinsics, predicted), intrinsics,
                                        predicted, options, anchors);
  ASSERT_TRUE(result.ok) << result.reason;
  const double shift = (result.cam_from_volume.translation() - truth.translation()).norm();
  const double off =
      Eigen::AngleAxisd(result.cam_from_volume.rotation() * truth.rotation().transpose()).angle() *
      180 / M_PI;
  std::printf(
      "one fingertip's anchors: centre %.3f mm off, turn %.3f° from the truth (10° "
      "predicted)\n",
      shift, off);
  EXPECT_LT(shift, 0.3);
  EXPECT_LT(off, 1.0);

  // With the ball's outline (silhouette.h): its turns stay free and the anchors still turn it.
  // The outline's normals are a few degrees off (whole pixels), which joined with the surface
  // would have made the turns look fixed.
  std::vector<std::uint8_t> mask(frame.depth_mm.size());
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = frame.depth_mm[i] != 0;
  IcpContour contour;
  contour.points =
      FindContour(frame, mask, {0, 0, frame.width, frame.height}, intrinsics, SilhouetteOptions());
  contour.pairable = &mask;
  const RaycastImage model = volume.Raycast(intrinsics, predicted);
  const IcpResult alone =
      AlignToModel(points, model, intrinsics, predicted, IcpOptions(), {}, &contour);
  const IcpResult anchored =
      AlignToModel(points, model, intrinsics, predicted, IcpOptions(), anchors, &contour);
  std::printf(
      "with the outline (%d of %zu points paired): alone turned %.3f° from the prediction, "
      "anchored %.3f° from the truth\n",
      alone.contour_pairs, contour.points.size(), TurnBetween(alone.cam_from_volume, turned),
      TurnBetween(anchored.cam_from_volume, truth));
  EXPECT_GT(contour.points.size(), 200u);
  EXPECT_EQ(alone.free_directions, 3) << "a ball's three turns, whatever its outline";
  EXPECT_LT(TurnBetween(alone.cam_from_volume, turned), 0.2);
  EXPECT_LT((alone.cam_from_volume.translation() - truth.translation()).norm(), 0.3);
  EXPECT_EQ(anchored.free.size(), 3u);
  EXPECT_LT(TurnBetween(anchored.cam_from_volume, truth), 1.0);
}

TEST(IcpSphereTest, AStartOffTheCastPoseKeepsItsOwnFreeTurn) {
  // The model cast at a prediction turned 10° and shifted 4 mm; ICP started from another pose,
  // turned 3° from that prediction about another axis and shifted 2 mm, against the same cast
  // (ObjectFusion's second ICP after the hand's turn is blended in): the ball's turn stays
  // the start's, its centre goes where the surface puts it.
  const Ball ball;
  const Rigid3 predicted = Rigid3::Translation({4, 0, 0}) * ball.truth *
                           Rigid3::FromAxisAngle(Eigen::Vector3d(0.2, 1, 0.4), 10 * M_PI / 180);
  const Rigid3 start = Rigid3::Translation({0, 2, 0}) * predicted *
                       Rigid3::FromAxisAngle(Eigen::Vector3d(1, 0, 0.3), 3 * M_PI / 180);
  const RaycastImage model = ball.volume.Raycast(ball.intrinsics, predicted);
  const IcpResult from_start = AlignToModel(ball.points, model, ball.intrinsics, predicted,
                                            IcpOptions(), {}, nullptr, &start);
  const IcpResult from_cast = AlignToModel(ball.points, model, ball.intrinsics, predicted);
  ASSERT_TRUE(from_start.ok) << from_start.reason;
  ASSERT_TRUE(from_cast.ok) << from_cast.reason;
  const double shift = (from_start.cam_from_volume.translation() - ball.truth.translation()).norm();
  std::printf(
      "from the start: centre %.3f mm off, turned %.3f° from the start (%.3f° from the "
      "cast pose); from the cast pose: %.3f° from the start\n",
      shift, TurnBetween(from_start.cam_from_volume, start),
      TurnBetween(from_start.cam_from_volume, predicted),
      TurnBetween(from_cast.cam_from_volume, start));
  EXPECT_EQ(from_start.free_directions, 3) << "a ball's three turns";
  EXPECT_LT(shift, 0.3);
  EXPECT_LT(TurnBetween(from_start.cam_from_volume, start), 0.2);
  EXPECT_GT(TurnBetween(from_cast.cam_from_volume, start), 2.5) << "the start made no difference";
}

}  // namespace
}  // namespace ihs::fusion
