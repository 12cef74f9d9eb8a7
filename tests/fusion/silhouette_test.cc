// Tests of ICP's silhouette term: the frame's occluding contour (against the background, not
// the hand) and the shift of a face seen head-on, which its own depth cannot fix.

#include "fusion/silhouette.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "fusion/icp.h"

namespace ihs::fusion {
namespace {

constexpr double kDepth = 600;

// A 60 × 60 mm square face at 600 mm, centred at (`shift_x`, `shift_y`) mm: its depth image
// (with a wall at 900 mm on the left half of the image and nothing on the right), its mask and
// its points.
struct Square {
  Frame frame;
  std::vector<std::uint8_t> mask;
  std::vector<Eigen::Vector3f> points;
  std::array<int, 4> box = {0, 0, 0, 0};
};

Square MakeSquare(const CameraIntrinsics& intrinsics, double shift_x, double shift_y) {
  Square square;
  Frame& frame = square.frame;
  frame.width = intrinsics.width, frame.height = intrinsics.height;
  const size_t pixels = static_cast<size_t>(frame.width) * frame.height;
  frame.depth_mm.assign(pixels, 0);
  square.mask.assign(pixels, 0);
  square.box = {frame.width, frame.height, 0, 0};
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const size_t pixel = static_cast<size_t>(v) * frame.width + u;
      const Eigen::Vector3d p = intrinsics.BackProject(u, v, kDepth);
      if (std::abs(p.x() - shift_x) <= 30 && std::abs(p.y() - shift_y) <= 30) {
        frame.depth_mm[pixel] = static_cast<std::uint16_t>(kDepth);
        square.mask[pixel] = 1;
        square.points.push_back(p.cast<float>());
        square.box = {std::min(square.box[0], u), std::min(square.box[1], v),
                      std::max(square.box[2], u + 1), std::max(square.box[3], v + 1)};
      } else if (u < frame.width / 2) {
        frame.depth_mm[pixel] = 900;
      }
    }
  }
  return square;
}

// The model's raycast of the square at its place (no shift), its normals a little noisy as a
// fused model's are (so that ICP can tell what its surface leaves free).
RaycastImage SquareModel(const CameraIntrinsics& intrinsics) {
  const Square square = MakeSquare(intrinsics, 0, 0);
  RaycastImage model;
  model.width = intrinsics.width, model.height = intrinsics.height;
  const size_t pixels = static_cast<size_t>(model.width) * model.height;
  model.depth_mm.assign(pixels, 0.0f);
  model.normals.assign(pixels, Eigen::Vector3f::Zero());
  model.colors.assign(pixels, {0, 0, 0});
  model.written = {0, 0, model.width, model.height};
  for (size_t pixel = 0; pixel < pixels; ++pixel) {
    if (!square.mask[pixel]) continue;
    model.depth_mm[pixel] = static_cast<float>(kDepth);
    const double u = static_cast<double>(pixel % model.width),
                 v = static_cast<double>(pixel / model.width);
    model.normals[pixel] = Eigen::Vector3f(0.02f * std::sin(1.7 * u + 0.3 * v),
                                           0.02f * std::cos(0.9 * v - 1.1 * u), -1)
                               .normalized();
  }
  return model;
}

TEST(SilhouetteTest, TheContourRunsAlongTheBackgroundAndNotAlongTheHand) {
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  Square square = MakeSquare(intrinsics, 0, 0);
  // A finger across the square's lower edge, 50 mm nearer: its pixels leave the mask.
  const int hand_top = square.box[3] - 8;
  for (int v = hand_top; v < square.box[3] + 10; ++v) {
    for (int u = 300; u < 340; ++u) {
      const size_t pixel = static_cast<size_t>(v) * intrinsics.width + u;
      square.frame.depth_mm[pixel] = static_cast<std::uint16_t>(kDepth - 50);
      square.mask[pixel] = 0;
    }
  }
  const SilhouetteOptions options;
  const std::vector<ContourPoint> contour =
      FindContour(square.frame, square.mask, square.box, intrinsics, options);
  ASSERT_GT(contour.size(), 100u);
  const Eigen::Vector2d centre = intrinsics.Project(Eigen::Vector3d(0, 0, kDepth));
  int near_hand = 0;
  for (const ContourPoint& point : contour) {
    const Eigen::Vector2d pixel = intrinsics.Project(point.point);
    // On the square's edge, pointing out of it.
    EXPECT_NEAR(point.point.z(), kDepth, 1e-6);
    EXPECT_GT(point.normal.dot(pixel - centre), 0.5 * (pixel - centre).norm());
    const bool by_finger = pixel.x() >= 297 && pixel.x() <= 342 && pixel.y() >= hand_top - 3;
    near_hand += by_finger;
  }
  // Not within 3 pixels of the finger, which covers the edge: the square goes on behind it.
  EXPECT_EQ(near_hand, 0);
  SilhouetteOptions bad;
  bad.search_px = 0;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
  bad = SilhouetteOptions();
  bad.weight = -1;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

TEST(SilhouetteTest, TheOutlineFixesTheShiftOfAFaceSeenHeadOn) {
  // A face seen head-on fixes its distance and tilt, not its shift along itself: ICP keeps that
  // at the prediction. The face's outline against the background fixes it.
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  const RaycastImage model = SquareModel(intrinsics);
  const double shift_x = 3.0, shift_y = -2.0;
  const Square seen = MakeSquare(intrinsics, shift_x, shift_y);
  const Rigid3 predicted;
  const IcpResult surface_only = AlignToModel(seen.points, model, intrinsics, predicted);
  IcpContour contour;
  contour.points = FindContour(seen.frame, seen.mask, seen.box, intrinsics, SilhouetteOptions());
  contour.pairable = &seen.mask;
  const IcpResult with_outline =
      AlignToModel(seen.points, model, intrinsics, predicted, IcpOptions(), {}, &contour);
  const Eigen::Vector3d truth(shift_x, shift_y, 0);
  std::printf(
      "a face seen 3.6 mm off along itself: %.2f mm off with its surface alone, %.2f mm with "
      "its outline (%d of %zu outline points paired)\n",
      (surface_only.cam_from_volume.translation() - truth).norm(),
      (with_outline.cam_from_volume.translation() - truth).norm(), with_outline.contour_pairs,
      contour.points.size());
  ASSERT_TRUE(surface_only.ok) << surface_only.reason;
  ASSERT_TRUE(with_outline.ok) << with_outline.reason;
  // The surface leaves the shifts along the face free (and the turn about its normal).
  EXPECT_GE(surface_only.free_directions, 3);
  EXPECT_EQ(with_outline.free_directions, 1);
  EXPECT_GT((surface_only.cam_from_volume.translation() - truth).norm(), 3.0);
  // Both outlines are whole pixels: within half a pixel at 600 mm (0.57 mm).
  EXPECT_LT((with_outline.cam_from_volume.translation() - truth).norm(), 0.6);
  EXPECT_GT(with_outline.contour_pairs, 100);
  // Where the outline agrees with the model, it moves nothing.
  const Square still = MakeSquare(intrinsics, 0, 0);
  IcpContour agreeing;
  agreeing.points =
      FindContour(still.frame, still.mask, still.box, intrinsics, SilhouetteOptions());
  agreeing.pairable = &still.mask;
  const IcpResult steady =
      AlignToModel(still.points, model, intrinsics, predicted, IcpOptions(), {}, &agreeing);
  EXPECT_LT(steady.cam_from_volume.translation().norm(), 0.3);
}

TEST(SilhouetteTest, OnlyAnEdgeWhoseSurfaceStillFacesTheCameraCounts) {
  // A crease (the square's face ends) is an edge; where the model's surface turns away from the
  // camera (a ball's outline) its last pixel falls short of the true outline and is not used.
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  RaycastImage model = SquareModel(intrinsics);
  const Square seen = MakeSquare(intrinsics, 1.5, 0);
  const std::vector<ContourPoint> contour =
      FindContour(seen.frame, seen.mask, seen.box, intrinsics, SilhouetteOptions());
  const double facing = SilhouetteOptions().min_edge_facing;
  auto paired = [&](const RaycastImage& image) {
    int count = 0;
    double sum = 0;
    for (const ContourPoint& point : contour) {
      Eigen::Vector3d direction;
      double residual = 0;
      if (!PairContourPoint(point.point, point.normal, image, intrinsics, 5.0, 4, facing,
                            &direction, &residual)) {
        continue;
      }
      ++count;
      // The right edge is 1.5 mm out: the frame's edge lies beyond the model's.
      if (point.normal.x() > 0.9) sum += residual;
    }
    return std::make_pair(count, sum);
  };
  const auto [crease, residuals] = paired(model);
  EXPECT_GT(crease, static_cast<int>(contour.size() * 9 / 10));
  EXPECT_GT(residuals, 0);
  for (Eigen::Vector3f& normal : model.normals) {
    if (normal.squaredNorm() > 0) normal = Eigen::Vector3f(0.98f, 0, -0.2f).normalized();
  }
  EXPECT_EQ(paired(model).first, 0) << "surface turned away at every edge";
}

}  // namespace
}  // namespace ihs::fusion
