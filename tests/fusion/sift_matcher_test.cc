// SIFT matches between two views of a textured square: they give the square's motion, and only
// masked pixels are searched.

#include "fusion/sift_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>

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

// The object's pixels in the image's left half only (the right half is "hand").
std::vector<std::uint8_t> LeftHalf(const Frame& frame) {
  std::vector<std::uint8_t> mask = DepthMask(frame);
  for (int p = 0; p < frame.PixelCount(); ++p) mask[p] = mask[p] && p % frame.width < 320;
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

TEST(SiftMatcherTest, AKeypointMatchedFromFrameToFrameKeepsItsTrack) {
  // Three views of the square moving 2 mm a frame: a match in the third frame whose keypoint
  // was matched in the second carries the same id (its previous point is where the second
  // frame's match saw it); within a frame no id is given twice.
  const Rigid3 pose = Rigid3::Translation({0, 0, 600}) * Rigid3::FromAxisAngle({1, 0.5, 0}, 0.3);
  SiftMatcher matcher(kIntrinsics);
  std::vector<std::vector<PointMatch>> frames;
  for (int i = 0; i < 3; ++i) {
    const Frame frame = RenderSquare(Rigid3::Translation({2.0 * i, 0, 0}) * pose);
    frames.push_back(matcher.Match(frame, DepthMask(frame)));
  }
  std::map<int, Eigen::Vector3d> seen_second;
  for (const PointMatch& m : frames[1]) {
    EXPECT_GE(m.id, 0);
    EXPECT_TRUE(seen_second.emplace(m.id, m.current).second) << "id " << m.id << " twice";
  }
  int continued = 0, on_spot = 0;
  std::set<int> ids_third;
  for (const PointMatch& m : frames[2]) {
    EXPECT_TRUE(ids_third.insert(m.id).second) << "id " << m.id << " twice";
    const auto found = seen_second.find(m.id);
    if (found == seen_second.end()) continue;
    ++continued;
    EXPECT_LT((found->second - m.previous).norm(), 1e-9);
    // The same spot of the square, moved 2 mm (a pixel is 1 mm there).
    if ((m.current - m.previous - Eigen::Vector3d(2, 0, 0)).norm() < 1.5) ++on_spot;
  }
  std::printf("%zu and %zu matches, %d tracks going on into the third frame, %d on their spot\n",
              frames[1].size(), frames[2].size(), continued, on_spot);
  EXPECT_GT(continued, 0.5 * frames[2].size());
  EXPECT_GE(on_spot, 0.9 * continued);
}

TEST(SiftMatcherTest, OnlyMaskedPixelsAreSearched) {
  const Rigid3 pose = Rigid3::Translation({0, 0, 600});
  const Frame a = RenderSquare(pose), b = RenderSquare(Rigid3::Translation({2, 0, 0}) * pose);
  SiftMatcher matcher(kIntrinsics);
  matcher.Match(a, LeftHalf(a));
  const std::vector<PointMatch> matches = matcher.Match(b, LeftHalf(b));
  EXPECT_GT(matches.size(), 20u);
  for (const PointMatch& m : matches) {
    EXPECT_LT(kIntrinsics.Project(m.current).x(), 320.5);
    EXPECT_LT(kIntrinsics.Project(m.previous).x(), 320.5);
  }
  Frame no_colour = b;
  no_colour.rgb.clear();
  EXPECT_TRUE(matcher.Match(no_colour, DepthMask(b)).empty());
}

TEST(SiftMatcherTest, KeypointsWhoseNeighbourhoodReachesOffTheObjectCanBeLeftOut) {
  // The square's left half is the object: keypoints near its right edge describe pixels of the
  // other half too. With support_inside = 4 no kept keypoint lies nearer the edge than twice
  // its size (OpenCV's smallest SIFT keypoints are 1.6 px across).
  const Rigid3 pose = Rigid3::Translation({0, 0, 600});
  const Frame a = RenderSquare(pose), b = RenderSquare(Rigid3::Translation({2, 0, 0}) * pose);
  auto nearest_to_edge = [](const std::vector<PointMatch>& matches) {
    double nearest = 1e9;
    for (const PointMatch& m : matches) {
      nearest = std::min(nearest, 320.0 - kIntrinsics.Project(m.current).x());
    }
    return nearest;
  };
  SiftOptions inside;
  inside.support_inside = 4.0;
  SiftMatcher any(kIntrinsics), whole(kIntrinsics, inside);
  any.Match(a, LeftHalf(a));
  whole.Match(a, LeftHalf(a));
  const std::vector<PointMatch> all = any.Match(b, LeftHalf(b));
  const std::vector<PointMatch> kept = whole.Match(b, LeftHalf(b));
  std::printf(
      "%zu matches, %zu with their neighbourhood on the object; nearest the edge %.1f / "
      "%.1f px\n",
      all.size(), kept.size(), nearest_to_edge(all), nearest_to_edge(kept));
  EXPECT_GT(kept.size(), 10u);
  EXPECT_LT(kept.size(), all.size());
  EXPECT_LT(nearest_to_edge(all), 2.0);
  EXPECT_GT(nearest_to_edge(kept), 2.0);
  inside.support_inside = -1;
  EXPECT_THROW(inside.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion
