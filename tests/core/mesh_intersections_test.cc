// Self-intersections: closed meshes that pass through themselves, against ones that only touch.

#include "core/mesh_intersections.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "tests/mesh_fixtures.h"

namespace ihs {
namespace {

TEST(MeshIntersectionsTest, ClosedSurfacesThatDoNotCrossHaveNone) {
  const TriangleMesh sphere = test::MakeUvSphere(35, 24, 48);
  EXPECT_EQ(FindSelfIntersections(sphere).pairs, 0);
  EXPECT_TRUE(IsWatertightWithoutSelfIntersections(sphere));
  // Two cubes apart, and two touching face to face: not crossing.
  const TriangleMesh cube = test::MakeCube(10);
  EXPECT_EQ(FindSelfIntersections(test::MergeMeshes(cube, cube, {30, 0, 0})).pairs, 0);
  EXPECT_EQ(FindSelfIntersections(test::MergeMeshes(cube, cube, {10, 0, 0})).pairs, 0);
  EXPECT_EQ(FindSelfIntersections(TriangleMesh{}).pairs, 0);
}

TEST(MeshIntersectionsTest, TwoOverlappingClosedPartsCross) {
  // Each cube is closed and oriented, so the merged mesh passes the edge test; their surfaces
  // cross along a closed line, through faces of both.
  const TriangleMesh cube = test::MakeCube(10);
  const TriangleMesh merged = test::MergeMeshes(cube, cube, {4, 3, 2});
  ASSERT_TRUE(merged.IsWatertight());
  const SelfIntersections found = FindSelfIntersections(merged, 100);
  EXPECT_GT(found.pairs, 0);
  EXPECT_FALSE(IsWatertightWithoutSelfIntersections(merged));
  for (const auto& [f, g] : found.examples) {
    EXPECT_LT(f, 12);  // One face of each cube.
    EXPECT_GE(g, 12);
  }
}

TEST(MeshIntersectionsTest, ASurfaceFoldedThroughItselfIsFound) {
  // The sphere's north pole pushed down through its south side: still closed and oriented, the
  // faces round the pole now cross the ones at the bottom.
  TriangleMesh sphere = test::MakeUvSphere(35, 24, 48);
  ASSERT_EQ(FindSelfIntersections(sphere).pairs, 0);
  int pole = -1;
  for (int v = 0; v < static_cast<int>(sphere.vertices.size()); ++v) {
    if (pole < 0 || sphere.vertices[v].z() > sphere.vertices[pole].z()) pole = v;
  }
  sphere.vertices[pole] = {0, 0, -50};
  ASSERT_TRUE(sphere.IsWatertight());
  const SelfIntersections found = FindSelfIntersections(sphere, 1000);
  EXPECT_GT(found.pairs, 0);
  // Every pair found has a face at the pole.
  for (const auto& [f, g] : found.examples) {
    const auto& a = sphere.faces[f];
    const auto& b = sphere.faces[g];
    const bool at_pole = std::find(a.begin(), a.end(), pole) != a.end() ||
                         std::find(b.begin(), b.end(), pole) != b.end();
    EXPECT_TRUE(at_pole) << f << " " << g;
  }
}

}  // namespace
}  // namespace ihs
