// Taking the posed hand model's pixels out of the object mask.

#include "fusion/object_mask.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/mesh_fixtures.h"

namespace ihs::fusion {
namespace {

// A flat wall at `depth_mm`, all of it object.
Frame Wall(const CameraIntrinsics& intrinsics, std::uint16_t depth_mm) {
  Frame frame = Frame::Blank(intrinsics.width, intrinsics.height);
  std::fill(frame.depth_mm.begin(), frame.depth_mm.end(), depth_mm);
  return frame;
}

TEST(ObjectMaskTest, AModelInFrontOfTheSurfaceIsCutOutGrownByTheDilation) {
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  const Frame frame = Wall(intrinsics, 800);
  const TriangleMesh ball = test::MakeUvSphere(20, 24, 48, {0, 0, 600});
  // The ball's outline is a disc of about fx·20/600 px radius (slightly more: it is a sphere).
  const double radius_px = intrinsics.fx * 20 / std::sqrt(600.0 * 600.0 - 20.0 * 20.0);
  for (int dilation : {0, 4}) {
    std::vector<std::uint8_t> mask(frame.depth_mm.size(), 1);
    const int cleared = RemoveMeshPixels(ball, frame, intrinsics, dilation, 10.0, &mask);
    const double expected = M_PI * (radius_px + dilation) * (radius_px + dilation);
    EXPECT_NEAR(cleared, expected, 0.05 * expected) << "dilation " << dilation;
    // The centre pixel is out, a far corner is still in.
    const int centre =
        static_cast<int>(intrinsics.cy) * frame.width + static_cast<int>(intrinsics.cx);
    EXPECT_EQ(mask[centre], 0);
    EXPECT_EQ(mask[0], 1);
  }
}

TEST(ObjectMaskTest, AModelBehindTheObservedSurfaceLeavesTheMaskAlone) {
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  const Frame frame = Wall(intrinsics, 500);
  std::vector<std::uint8_t> mask(frame.depth_mm.size(), 1);
  const TriangleMesh ball = test::MakeUvSphere(20, 24, 48, {0, 0, 600});
  EXPECT_EQ(RemoveMeshPixels(ball, frame, intrinsics, 3, 10.0, &mask), 0);
  // Behind the camera or empty: nothing either.
  const TriangleMesh behind = test::MakeUvSphere(20, 24, 48, {0, 0, -600});
  EXPECT_EQ(RemoveMeshPixels(behind, frame, intrinsics, 3, 10.0, &mask), 0);
  EXPECT_EQ(RemoveMeshPixels(TriangleMesh{}, frame, intrinsics, 3, 10.0, &mask), 0);
}

}  // namespace
}  // namespace ihs::fusion
