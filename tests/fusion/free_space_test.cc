// Where the views saw the object is not: through the rays in front of the measured depth, where
// the sensor measured nothing, and inside the posed hand; against a cube rendered analytically.

#include "fusion/free_space.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/free_space_fixtures.h"
#include "tests/mesh_fixtures.h"

namespace ihs::fusion {
namespace {

using test::CubeView;
using test::kCubeEdgeMm;

const CameraIntrinsics kCamera = CameraIntrinsics::Carmine109();

// The camera 400 mm from the cube's centre, the cube turned by `deg` about y.
Rigid3 Turned(double deg, double distance_mm = 400) {
  return Rigid3::Translation({0, 0, distance_mm}) *
         Rigid3::FromAxisAngle({0, 1, 0}, deg * M_PI / 180);
}

// Keeps the views of the cube at `poses` (each rendered where it is).
FreeSpace Views(std::initializer_list<Rigid3> poses, FreeSpaceOptions options = {}) {
  options.min_turn_deg = 0;
  FreeSpace free_space(kCamera, options);
  for (const Rigid3& pose : poses) {
    const test::RenderedView view = CubeView(kCamera, pose);
    free_space.Observe(view.frame, view.object_box, pose);
  }
  return free_space;
}

TEST(FreeSpaceTest, KeepsAFrameOnlyWhenTheObjectTurnedFromEveryKeptView) {
  FreeSpaceOptions options;
  options.min_turn_deg = 4;
  options.max_views = 3;
  FreeSpace free_space(kCamera, options);
  auto observe = [&](double deg) {
    const test::RenderedView view = CubeView(kCamera, Turned(deg));
    return free_space.Observe(view.frame, view.object_box, Turned(deg));
  };
  EXPECT_TRUE(observe(0));
  EXPECT_FALSE(observe(2));   // Too near the first.
  EXPECT_TRUE(observe(5));
  EXPECT_FALSE(observe(1));   // Too near the first again.
  EXPECT_TRUE(observe(-5));
  EXPECT_FALSE(observe(20));  // Full.
  EXPECT_EQ(free_space.views(), 3);
}

TEST(FreeSpaceTest, SpaceInFrontOfTheSurfaceIsEmptyOnceTwoViewsSawThroughIt) {
  const Eigen::Vector3f in_front(0, 0, -kCubeEdgeMm / 2 - 20);  // Between camera and cube.
  const Eigen::Vector3f inside(0, 0, 0);
  const Eigen::Vector3f behind(0, 0, kCubeEdgeMm / 2 + 20);  // Hidden by the cube.
  EXPECT_LT(Views({Turned(0)}).Emptiness(in_front, 3), 0);  // One view is not enough.
  const FreeSpace two = Views({Turned(0), Turned(5)});
  EXPECT_FLOAT_EQ(two.Emptiness(in_front, 3), 3);
  EXPECT_LT(two.Emptiness(inside, 3), 0);
  EXPECT_LT(two.Emptiness(behind, 3), 0);
  // Nearer the surface than the margin: the TSDF's to decide.
  const Eigen::Vector3f near(0, 0, -kCubeEdgeMm / 2 - 3);
  EXPECT_LT(two.Emptiness(near, 3), 0);
  // Between the margin and the limit the value is the distance past the margin.
  const Eigen::Vector3f past(0, 0, -kCubeEdgeMm / 2 - 7.5f);
  EXPECT_NEAR(two.Emptiness(past, 3), 2.0, 0.6);  // Depth rounded to whole mm.
}

TEST(FreeSpaceTest, ReposedViewsSeeTheSpaceWhereTheCorrectionMovedIt) {
  // Two views kept with the object frame 30 mm off along x (as a drift would leave them),
  // then corrected: the cube's inside is where it is again, not 30 mm aside.
  const Rigid3 off = Rigid3::Translation({30, 0, 0});
  FreeSpaceOptions options;
  options.min_turn_deg = 0;
  FreeSpace free_space(kCamera, options);
  int stamp = 0;
  for (const Rigid3& pose : {Turned(0), Turned(5)}) {
    const test::RenderedView view = CubeView(kCamera, pose);
    free_space.Observe(view.frame, view.object_box, pose * off, nullptr, stamp++);
  }
  // The cube's centre; the point the off views took for it.
  const Eigen::Vector3f centre(0, 0, 0);
  const Eigen::Vector3f taken(-30, 0, 0);
  EXPECT_GT(free_space.Emptiness(centre, 3), 0);
  EXPECT_LT(free_space.Emptiness(taken, 3), 0);
  const FreeSpace before = free_space;  // Copies share views: Repose must not change them.
  std::vector<int> stamps;
  free_space.Repose([&](int view_stamp) {
    stamps.push_back(view_stamp);
    return off.Inverse();
  });
  EXPECT_EQ(stamps, (std::vector<int>{0, 1}));
  EXPECT_LT(free_space.Emptiness(centre, 3), 0);
  EXPECT_GT(free_space.Emptiness(taken, 3), 0);
  EXPECT_GT(before.Emptiness(centre, 3), 0);
}

TEST(FreeSpaceTest, PixelsWithoutDepthFarFromAnyWithDepthAreRaysThatMetNothing) {
  const Eigen::Vector3f beside(kCubeEdgeMm / 2 + 15, 0, 0);
  EXPECT_GT(Views({Turned(0), Turned(5)}).Emptiness(beside, 3), 0);
  FreeSpaceOptions measured_only;
  measured_only.no_depth_is_empty = false;
  EXPECT_LT(Views({Turned(0), Turned(5)}, measured_only).Emptiness(beside, 3), 0);
  // Right at the silhouette (within the radius of depth) a missing pixel says nothing.
  const Eigen::Vector3f at_edge(kCubeEdgeMm / 2 + 1.0f, 0, 0);
  EXPECT_LT(Views({Turned(0), Turned(5)}).Emptiness(at_edge, 3), 0);
}

TEST(FreeSpaceTest, TwoMisregisteredViewsDoNotOutvoteThreeThatSawTheSurface) {
  // Two views rendered with the cube 15 mm farther than their poses say: to them the space just
  // inside the front face looks empty.
  FreeSpaceOptions options;
  options.min_turn_deg = 0;
  FreeSpace free_space(kCamera, options);
  for (double deg : {0.0, 5.0, -5.0}) {
    const test::RenderedView view = CubeView(kCamera, Turned(deg));
    free_space.Observe(view.frame, view.object_box, Turned(deg));
  }
  const Eigen::Vector3f on_face(0, 0, -kCubeEdgeMm / 2 + 1);
  EmptinessVotes votes;
  EXPECT_LT(free_space.Emptiness(on_face, 3, &votes), 0);
  EXPECT_EQ(votes.at_surface, 3);
  for (double deg : {10.0, -10.0}) {
    const test::RenderedView view = CubeView(kCamera, Turned(deg, 400 + 15));
    free_space.Observe(view.frame, view.object_box, Turned(deg));
  }
  EXPECT_LT(free_space.Emptiness(on_face, 3, &votes), 0);
  EXPECT_EQ(votes.through, 2);
  EXPECT_EQ(votes.at_surface, 3);
}

TEST(FreeSpaceTest, TheHandsVolumeIsEmptyEvenWhereTheObjectHidesIt) {
  // A 24 mm "finger" cube right behind the object cube: no pixel sees it.
  TriangleMesh finger = test::MakeCube(24);
  const Eigen::Vector3f finger_centre(0, 0, kCubeEdgeMm / 2 + 12);
  FreeSpaceOptions options;
  options.min_turn_deg = 0;
  FreeSpace free_space(kCamera, options);
  for (double deg : {0.0, 3.0}) {
    const Rigid3 pose = Turned(deg);
    TriangleMesh hand = finger;
    for (auto& v : hand.vertices) v = pose * Eigen::Vector3f(v + finger_centre);
    const test::RenderedView view = CubeView(kCamera, pose);
    free_space.Observe(view.frame, view.object_box, pose, &hand);
  }
  EmptinessVotes votes;
  EXPECT_GT(free_space.Emptiness(finger_centre, 3, &votes), 0);
  EXPECT_EQ(votes.in_hand, 2);
  // Past the finger's far side, and within the margin of its near side (the object's face).
  EXPECT_LT(free_space.Emptiness(finger_centre + Eigen::Vector3f(0, 0, 14), 3), 0);
  EXPECT_LT(free_space.Emptiness(finger_centre - Eigen::Vector3f(0, 0, 9), 3), 0);
}

TEST(FreeSpaceTest, NoViewsNoEvidence) {
  const FreeSpace none;
  EXPECT_EQ(none.views(), 0);
  EXPECT_LT(none.Emptiness({0, 0, -100}, 3), 0);
  FreeSpaceOptions off;
  off.enabled = false;
  FreeSpace disabled(kCamera, off);
  const test::RenderedView view = CubeView(kCamera, Turned(0));
  EXPECT_FALSE(disabled.Observe(view.frame, view.object_box, Turned(0)));
}

TEST(FreeSpaceTest, BadOptionsAreRejected) {
  FreeSpaceOptions bad;
  bad.min_views = 0;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
  bad = {};
  bad.margin_mm = -1;
  EXPECT_THROW(FreeSpace(kCamera, bad), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion
