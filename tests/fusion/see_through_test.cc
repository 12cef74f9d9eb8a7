// The model's pixels against the frame's depth: what the frame sees through, sampled, the
// model's edges left out; where the hand covers the model.

#include "fusion/see_through.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>

namespace ihs::fusion {
namespace {

const CameraIntrinsics kIntrinsics = CameraIntrinsics::Carmine109();

// The model as a raycast: a square at 600 mm over pixels [200, 300) both ways.
RaycastImage ModelSquare() {
  RaycastImage model;
  model.width = kIntrinsics.width, model.height = kIntrinsics.height;
  model.depth_mm.assign(static_cast<size_t>(model.width) * model.height, 0.0f);
  for (int v = 200; v < 300; ++v) {
    for (int u = 200; u < 300; ++u) model.depth_mm[v * model.width + u] = 600.0f;
  }
  model.written = {0, 0, model.width, model.height};
  return model;
}

// A wall at 900 mm with the object's square at 600 mm over columns [u0, u0 + 100), rows
// [200, 300); columns [hand_u0, hand_u1) of those rows show a hand at 550 mm instead.
Frame Scene(int u0, int hand_u0 = 0, int hand_u1 = 0) {
  Frame frame = Frame::Blank(kIntrinsics.width, kIntrinsics.height, false);
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const bool rows = v >= 200 && v < 300;
      std::uint16_t depth = rows && u >= u0 && u < u0 + 100 ? 600 : 900;
      if (rows && u >= hand_u0 && u < hand_u1) depth = 550;
      frame.depth_mm[v * frame.width + u] = depth;
    }
  }
  return frame;
}

TEST(SeeThroughTest, AModelBesideTheObjectIsSeenThroughWhereItOverhangsTheBackground) {
  SeeThroughOptions options;
  options.step_px = 4;  // Samples at 2, 6, 10, ...: 25 columns and rows on the square.
  const RaycastImage model = ModelSquare();
  const SeeThrough there = MeasureSeeThrough(model, Scene(200), kIntrinsics, options);
  // The square's inner samples: 23 x 23 (its outermost ones left out).
  EXPECT_EQ(there.in_view, 23 * 23);
  EXPECT_EQ(there.through, 0);
  EXPECT_EQ(there.visible, 25 * 25);
  const Eigen::Vector3d centre = kIntrinsics.BackProject(250, 250, 600);
  EXPECT_NEAR((there.visible_centroid - centre).norm(), 0, 0.1 * 600 / kIntrinsics.fx);
  // The object 20 px to the right: the model's left columns 202-218 show the wall, of them
  // 206-218 inner ones.
  const SeeThrough beside = MeasureSeeThrough(model, Scene(220), kIntrinsics, options);
  EXPECT_EQ(beside.through, 4 * 23);
  EXPECT_DOUBLE_EQ(beside.share(), 4.0 / 23);
  EXPECT_EQ(beside.visible, 25 * 25);  // The wall hides nothing of the model.
}

TEST(SeeThroughTest, WhatIsInFrontOfTheModelIsNotSeenThroughNorWhatTheModelShows) {
  SeeThroughOptions options;
  options.step_px = 4;
  const RaycastImage model = ModelSquare();
  // The object where the model is, a hand over its left 40 columns (samples 202-238).
  const SeeThrough covered = MeasureSeeThrough(model, Scene(200, 200, 240), kIntrinsics, options);
  EXPECT_EQ(covered.through, 0);
  EXPECT_EQ(covered.visible, 15 * 25);
  const Eigen::Vector3d right_part = kIntrinsics.BackProject(270, 250, 600);
  EXPECT_NEAR((covered.visible_centroid - right_part).norm(), 0, 0.1 * 600 / kIntrinsics.fx);
  // No depth (a hole in the sensor's image) says nothing.
  Frame holes = Scene(220);
  for (auto& depth : holes.depth_mm) depth = 0;
  const SeeThrough nothing = MeasureSeeThrough(model, holes, kIntrinsics, options);
  EXPECT_EQ(nothing.in_view, 0);
  EXPECT_EQ(nothing.share(), 0.0);
  // A margin wider than the wall's 300 mm behind the model: nothing seen through.
  options.margin_mm = 400;
  EXPECT_EQ(MeasureSeeThrough(model, Scene(220), kIntrinsics, options).through, 0);
}

TEST(SeeThroughTest, ThePixelsToRaycastAreASampleWithDepth) {
  Frame frame = Scene(200);
  frame.depth_mm[6 * frame.width + 6] = 0;
  std::vector<std::uint16_t> near;
  SeeThroughPixels(frame, 4, &near);
  ASSERT_EQ(near.size(), frame.depth_mm.size());
  int cast = 0;
  for (size_t p = 0; p < near.size(); ++p) {
    if (near[p] == 0) continue;
    ++cast;
    const int u = static_cast<int>(p % frame.width), v = static_cast<int>(p / frame.width);
    EXPECT_EQ(u % 4, 2);
    EXPECT_EQ(v % 4, 2);
    EXPECT_EQ(near[p], frame.depth_mm[p]);
  }
  EXPECT_EQ(cast, 160 * 120 - 1);
}

TEST(SeeThroughTest, TheModelIsLookedForWhereTheObservedBoxProjects) {
  // A 100 mm cube 600 mm in front of the camera, centred on its axis.
  const Eigen::AlignedBox3f cube(Eigen::Vector3f::Constant(-50), Eigen::Vector3f::Constant(50));
  const Rigid3 ahead = Rigid3::Translation({0, 0, 600});
  const auto [u0, v0, u1, v1] = ImageBoxOf(cube, ahead, kIntrinsics);
  // Its widest at its near face, 550 mm away.
  const Eigen::Vector2d near_corner = kIntrinsics.Project({-50, -50, 550});
  const Eigen::Vector2d far_corner = kIntrinsics.Project({50, 50, 550});
  EXPECT_EQ(u0, static_cast<int>(std::floor(near_corner.x())));
  EXPECT_EQ(v0, static_cast<int>(std::floor(near_corner.y())));
  EXPECT_EQ(u1, static_cast<int>(std::ceil(far_corner.x())) + 1);
  EXPECT_EQ(v1, static_cast<int>(std::ceil(far_corner.y())) + 1);
  // Reaching behind the camera: the whole image; wholly beside it: a sliver at its edge.
  EXPECT_EQ(ImageBoxOf(cube, Rigid3::Translation({0, 0, 30}), kIntrinsics),
            (std::array<int, 4>{0, 0, 0, 0}));
  const auto beside = ImageBoxOf(cube, Rigid3::Translation({2000, 0, 600}), kIntrinsics);
  EXPECT_EQ(beside[0], kIntrinsics.width - 1);
  EXPECT_EQ(beside[2], kIntrinsics.width);
  EXPECT_EQ(ImageBoxOf(Eigen::AlignedBox3f(), ahead, kIntrinsics),
            (std::array<int, 4>{0, 0, 0, 0}));
}

TEST(SeeThroughTest, BadOptionsAreRefused) {
  SeeThroughOptions options;
  options.max_share = 1.5;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.step_px = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.margin_mm = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  EXPECT_NO_THROW(SeeThroughOptions().Check());
  const RaycastImage model = ModelSquare();
  EXPECT_THROW(MeasureSeeThrough(model, Frame::Blank(320, 240, false), kIntrinsics, {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion
