// SIFT matches between two views of a textured square: they give the square's motion, and only
// masked pixels are searched.

#include "fusion/sift_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace ihs::fusion {
namespace {

const CameraIntrinsics kIntrinsics = CameraIntrinsics::Carmine109();

// A 140 mm square in its frame's z = 0 plane, covered with 4 mm cells of pseudo-random colour,
// seen by a camera at `cam_from_square`.
Frame RenderSquare(const Rigid3& cam_from_square) {
  Frame frame = Frame::Blank(kIntrinsics.width, kIntrinsics.height, true);
  const Rigid3 square_from_cam = cam_from_square.Inverse();
  const Eigen::Vector3d origin = square_from_cam.translation();
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const Eigen::Vector3d ray = kIntrinsics.BackProject(u, v, 1.0);
      const Eigen::Vector3d direction = square_from_cam.RotateVector(ray);
      if (std::abs(direction.z()) < 1e-9) continue;
      const double t = -origin.z() / direction.z();
      const Eigen::Vector3d hit = origin + t * direction;
      if (t <= 0 || std::abs(hit.x()) > 70 || std::abs(hit.y()) > 70) continue;
      const int pixel = v * frame.width + u;
      frame.depth_mm[pixel] = static_cast<std::uint16_t>(std::lround(t * ray.z()));
      const auto cx = static_cast<std::uint32_t>(std::floor(hit.x() / 4) + 1000);
      const auto cy = static_cast<std::uint32_t>(std::floor(hit.y() / 4) + 1000);
      std::uint32_t hash = cx * 73856093u ^ cy * 19349663u;
      hash ^= hash >> 13, hash *= 0x5bd1e995u, hash ^= hash >> 15;
      for (int c = 0; c < 3; ++c)
        frame.rgb[3 * pixel + c] = static_cast<std::uint8_t>(hash >> (8 * c));
    }
  }
  return frame;
}

std::vector<std::uint8_t> DepthMask(const Frame& frame) {
  std::vector<std::uint8_t> mask(frame.depth_mm.size());
  for (size_t p = 0; p < mask.size(); ++p) mask[p] = frame.depth_mm[p] != 0;
  return mask;
}

TEST(SiftMatcherTest, MatchesOfATexturedSquareGiveItsMotion) {
  const Rigid3 first = Rigid3::Translation({0, 0, 600}) * Rigid3::FromAxisAngle({1, 0.5, 0}, 0.3);
  const Rigid3 motion = Rigid3::Translation({0, 0, 600}) *
                        Rigid3::FromAxisAngle({0.2, 1, 0.3}, 4 * M_PI / 180, {3, -2, 1}) *
                        Rigid3::Translation({0, 0, -600});
  const Frame a = RenderSquare(first), b = RenderSquare(motion * first);
  SiftMatcher matcher(kIntrinsics);
  EXPECT_TRUE(matcher.Match(a, DepthMask(a)).empty());  // Nothing to match yet.
  const std::vector<PointMatch> matches = matcher.Match(b, DepthMask(b));
  PairwiseOptions visual_only;
  visual_only.contact_weight = 0;
  PairwiseInput input;
  input.Pairs(matcher.name(), matcher.kind()) = matches;
  const PairwiseResult result = RegisterPair(input, visual_only);
  ASSERT_TRUE(result.ok) << result.reason;
  double worst = 0;
  for (double x : {-70.0, 70.0})
    for (double y : {-70.0, 70.0}) {
      const Eigen::Vector3d corner = first * Eigen::Vector3d(x, y, 0);
      worst = std::max(worst, (result.current_from_previous * corner - motion * corner).norm());
    }
  std::printf("%zu matches, %d inliers: motion error %.2f mm at the corners\n", matches.size(),
              result.visual_inliers, worst);
  EXPECT_GT(matches.size(), 50u);
  EXPECT_GT(result.visual_inliers, 0.8 * matches.size());
  EXPECT_LT(worst, 1.5);
}

TEST(SiftMatcherTest, OnlyMaskedPixelsAreSearched) {
  const Rigid3 pose = Rigid3::Translation({0, 0, 600});
  const Frame a = RenderSquare(pose), b = RenderSquare(Rigid3::Translation({2, 0, 0}) * pose);
  // The right half of the image is "hand".
  auto left_half = [](const Frame& frame) {
    std::vector<std::uint8_t> mask = DepthMask(frame);
    for (int p = 0; p < frame.PixelCount(); ++p) mask[p] = mask[p] && p % frame.width < 320;
    return mask;
  };
  SiftMatcher matcher(kIntrinsics);
  matcher.Match(a, left_half(a));
  const std::vector<PointMatch> matches = matcher.Match(b, left_half(b));
  EXPECT_GT(matches.size(), 20u);
  for (const PointMatch& m : matches) {
    EXPECT_LT(kIntrinsics.Project(m.current).x(), 320.5);
    EXPECT_LT(kIntrinsics.Project(m.previous).x(), 320.5);
  }
  Frame no_colour = b;
  no_colour.rgb.clear();
  EXPECT_TRUE(matcher.Match(no_colour, DepthMask(b)).empty());
}

}  // namespace
}  // namespace ihs::fusion
