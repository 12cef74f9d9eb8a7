#include "core/camera_intrinsics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ihs {
namespace {

TEST(CameraIntrinsicsTest, DefaultsAreTheCarmineOfThePaper) {
  const CameraIntrinsics k = CameraIntrinsics::Carmine109();
  EXPECT_EQ(k.fx, 525.0);
  EXPECT_EQ(k.fy, 525.0);
  EXPECT_EQ(k.cx, 319.5);
  EXPECT_EQ(k.cy, 239.5);
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
}

TEST(CameraIntrinsicsTest, ProjectInvertsBackProject) {
  const CameraIntrinsics k;
  for (double u : {0.0, 100.25, 319.5, 639.0}) {
    for (double v : {0.0, 239.5, 479.0}) {
      const Eigen::Vector3d point = k.BackProject(u, v, 600.0);
      EXPECT_DOUBLE_EQ(point.z(), 600.0);
      const Eigen::Vector2d pixel = k.Project(point);
      EXPECT_NEAR(pixel.x(), u, 1e-9);
      EXPECT_NEAR(pixel.y(), v, 1e-9);
    }
  }
  // A point 100 mm right of the axis at 525 mm depth lands 100 px right of the centre.
  EXPECT_NEAR(k.Project({100, 0, 525}).x(), 419.5, 1e-12);
}

TEST(CameraIntrinsicsTest, FieldOfViewRoundTripsAndMatchesTheKinectRecording) {
  // The Kinect v1 recording in shared/data reports these fields of view: fx ≈ 575.8 px.
  const CameraIntrinsics kinect = CameraIntrinsics::FromFieldOfView(640, 480, 1.0144686, 0.7898059);
  EXPECT_NEAR(kinect.fx, 575.8, 0.1);
  EXPECT_NEAR(kinect.fy, 575.8, 0.1);
  EXPECT_EQ(kinect.cx, 319.5);
  const CameraIntrinsics k;
  const CameraIntrinsics again =
      CameraIntrinsics::FromFieldOfView(640, 480, k.HorizontalFovRad(), k.VerticalFovRad());
  EXPECT_NEAR(again.fx, 525.0, 1e-9);
  EXPECT_NEAR(again.fy, 525.0, 1e-9);
}

TEST(CameraIntrinsicsTest, ScalingKeepsRaysThroughTheSameImagePoints) {
  const CameraIntrinsics k;
  const CameraIntrinsics half = k.Scaled(320, 240);
  EXPECT_DOUBLE_EQ(half.fx, 262.5);
  EXPECT_DOUBLE_EQ(half.cx, 159.5);
  const Eigen::Vector3d point(30, -20, 700);
  const Eigen::Vector2d full_pixel = k.Project(point), half_pixel = half.Project(point);
  EXPECT_NEAR((full_pixel.x() + 0.5) / 2 - 0.5, half_pixel.x(), 1e-9);
  EXPECT_NEAR((full_pixel.y() + 0.5) / 2 - 0.5, half_pixel.y(), 1e-9);
}

TEST(CameraIntrinsicsTest, ContainsUsesPixelCentresAtIntegers) {
  const CameraIntrinsics k;
  EXPECT_TRUE(k.Contains(0, 0));
  EXPECT_TRUE(k.Contains(639.4, 479.4));
  EXPECT_FALSE(k.Contains(-0.6, 10));
  EXPECT_FALSE(k.Contains(639.6, 10));
}

TEST(CameraIntrinsicsTest, CheckNamesTheBadField) {
  CameraIntrinsics k;
  k.fy = 0;
  try {
    k.Check();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("intrinsics.fy"), std::string::npos);
  }
  EXPECT_THROW(CameraIntrinsics::FromFieldOfView(640, 480, 0.0, 0.8), std::invalid_argument);
  EXPECT_NO_THROW(CameraIntrinsics().Check());
}

}  // namespace
}  // namespace ihs
