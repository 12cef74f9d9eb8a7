// A closure that balloons past what the views saw is cut back to the space they did not see
// empty; one that stays inside it is left as it is.

#include "fusion/closure_bound.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/mesh_intersections.h"
#include "tests/free_space_fixtures.h"
#include "tests/mesh_fixtures.h"

namespace ihs::fusion {
namespace {

using test::kCubeEdgeMm;

// Views of the cube from a ring of directions about y, 30° apart, and from above and below.
FreeSpace RingOfViews() {
  const CameraIntrinsics camera = CameraIntrinsics::Carmine109();
  FreeSpace free_space(camera);
  auto observe = [&](const Rigid3& cube_turn) {
    const Rigid3 pose = Rigid3::Translation({0, 0, 450}) * cube_turn;
    const test::RenderedView view = test::CubeView(camera, pose);
    free_space.Observe(view.frame, view.object_box, pose);
  };
  for (int step = 0; step < 12; ++step) {
    observe(Rigid3::FromAxisAngle({0, 1, 0}, (step * 30 + 15) * M_PI / 180));
  }
  observe(Rigid3::FromAxisAngle({1, 0, 0}, M_PI / 2));
  observe(Rigid3::FromAxisAngle({1, 0, 0}, M_PI / 2 + 0.2));
  observe(Rigid3::FromAxisAngle({1, 0, 0}, -M_PI / 2));
  observe(Rigid3::FromAxisAngle({1, 0, 0}, -M_PI / 2 - 0.2));
  return free_space;
}

TEST(ClosureBoundTest, ABalloonThroughSpaceTheViewsSawEmptyIsCutBackToIt) {
  const FreeSpace free_space = RingOfViews();
  ASSERT_EQ(free_space.views(), 16);
  // Poisson's guess: a ball round the cube, 15 % past its corners, 4.2 times its volume.
  const TriangleMesh balloon = test::MakeUvSphere(kCubeEdgeMm, 32, 64);
  const TriangleMesh seen = test::MakeCube(kCubeEdgeMm);
  const ClosureBound bound = BoundByFreeSpace(balloon, seen, free_space, 1.0, 2.0, 0.05);
  ASSERT_TRUE(bound.changed);
  const TriangleMesh& mesh = bound.mesh;
  EXPECT_TRUE(mesh.IsWatertight());
  EXPECT_EQ(FindSelfIntersections(mesh, 0).pairs, 0);
  // What is left: the cube grown by the margin (5.5 mm) along the views' rays, and cut off the
  // corners where their silhouettes pass (1.63 times the cube when written).
  const double cube = std::pow(kCubeEdgeMm, 3);
  EXPECT_GT(mesh.Volume(), 0.9 * cube);
  EXPECT_LT(mesh.Volume(), 1.9 * cube);
  EXPECT_GT(bound.removed_share, 0.5);
  EXPECT_NEAR(bound.removed_share, 1 - mesh.Volume() / balloon.Volume(), 1e-9);
  // The ball reached 20 mm past the faces; what is left stays within 10 mm of them. Past the
  // margin it is thin fins along the edges where the ring's views graze the top and bottom
  // faces: as many views saw a surface there as saw through, and a tie is not empty.
  const float reach = kCubeEdgeMm / 2 + 10.0f;
  for (const auto& v : mesh.vertices) {
    ASSERT_LE(v.cwiseAbs().maxCoeff(), reach) << v.transpose();
    // Nothing left where the views saw empty space: a vertex lies within the lattice's step
    // (1 mm, along an axis: marching cubes puts it on a lattice edge) of a point they did not
    // see empty (a silhouette's edge, or a tie half a millimetre thick, falls between points).
    float least = free_space.Emptiness(v, 3);
    for (int axis = 0; axis < 3; ++axis) {
      for (float step : {-1.0f, -0.75f, -0.5f, -0.25f, 0.25f, 0.5f, 0.75f, 1.0f}) {
        Eigen::Vector3f moved = v;
        moved[axis] += step;
        least = std::min(least, free_space.Emptiness(moved, 3));
      }
    }
    ASSERT_LE(least, 0.0f) << v.transpose();
  }
  // Colours of the closed mesh carried over.
  TriangleMesh coloured = balloon;
  coloured.colors.assign(coloured.vertices.size(), {10, 200, 30});
  const ClosureBound with_colour = BoundByFreeSpace(coloured, seen, free_space, 1.0, 2.0, 0.05);
  ASSERT_TRUE(with_colour.mesh.HasColors());
  EXPECT_EQ(with_colour.mesh.colors.front(), (TriangleMesh::Color{10, 200, 30}));
}

TEST(ClosureBoundTest, TheSeenSurfaceIsNeverCut) {
  // A seen ball 10 mm wider than the cube the views saw (they were misregistered): the views
  // saw space empty around its poles and equator, but nothing within `keep_seen_mm` of it goes.
  const FreeSpace free_space = RingOfViews();
  const TriangleMesh big = test::MakeCube(kCubeEdgeMm + 30);
  const float radius = kCubeEdgeMm / 2 + 10;
  const TriangleMesh seen = test::MakeUvSphere(radius, 48, 96);
  const ClosureBound kept = BoundByFreeSpace(big, seen, free_space, 1.0, 3.0, 0.05);
  ASSERT_TRUE(kept.changed);
  Eigen::Vector3f reach = Eigen::Vector3f::Zero();
  for (const auto& v : kept.mesh.vertices) reach = reach.cwiseMax(v.cwiseAbs());
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GT(reach[axis], radius - 0.5f) << axis;  // The ball's extent stays.
    EXPECT_LT(reach[axis], radius + 3.5f) << axis;  // The big cube's does not.
  }
}

TEST(ClosureBoundTest, AClosureInsideWhatWasNotSeenEmptyIsLeftAsItIs) {
  const FreeSpace free_space = RingOfViews();
  const TriangleMesh inside = test::MakeUvSphere(kCubeEdgeMm * 0.45f, 16, 32);
  const TriangleMesh seen = test::MakeCube(kCubeEdgeMm);
  const ClosureBound bound = BoundByFreeSpace(inside, seen, free_space, 1.0, 2.0, 0.05);
  EXPECT_FALSE(bound.changed);
  EXPECT_EQ(bound.removed_share, 0);
  EXPECT_EQ(bound.mesh.vertices, inside.vertices);
  EXPECT_FALSE(BoundByFreeSpace(inside, seen, FreeSpace(), 1.0, 2.0, 0.05).changed);
}

}  // namespace
}  // namespace ihs::fusion
