#include "core/triangle_mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "tests/mesh_fixtures.h"

namespace ihs {
namespace {

TEST(TriangleMeshTest, CubeHasExactAreaVolumeAndBounds) {
  const TriangleMesh cube = test::MakeCube(10);
  EXPECT_NEAR(cube.SurfaceArea(), 600.0, 1e-9);
  EXPECT_NEAR(cube.Volume(), 1000.0, 1e-9);
  EXPECT_TRUE(cube.IsWatertight());
  const auto [lo, hi] = cube.Bounds();
  EXPECT_EQ(lo, Eigen::Vector3f(-5, -5, -5));
  EXPECT_EQ(hi, Eigen::Vector3f(5, 5, 5));
}

TEST(TriangleMeshTest, FineSphereApproachesTheAnalyticVolumeAndArea) {
  const TriangleMesh sphere = test::MakeUvSphere(35, 90, 180);  // The paper's Ø70 mm ball.
  EXPECT_TRUE(sphere.IsWatertight());
  const double volume = 4.0 / 3.0 * M_PI * 35 * 35 * 35;  // 179 594 mm³.
  EXPECT_NEAR(sphere.Volume() / volume, 1.0, 2e-3);
  EXPECT_NEAR(sphere.SurfaceArea() / (4 * M_PI * 35 * 35), 1.0, 2e-3);
}

TEST(TriangleMeshTest, WatertightnessDetectsHolesAndFlippedFaces) {
  TriangleMesh cube = test::MakeCube(10);
  cube.faces.pop_back();
  EXPECT_FALSE(cube.IsWatertight());
  cube = test::MakeCube(10);
  std::swap(cube.faces[0][1], cube.faces[0][2]);  // One face flipped inwards.
  EXPECT_FALSE(cube.IsWatertight());
  cube = test::MakeCube(10);
  cube.faces.push_back(cube.faces[0]);  // A duplicated face makes an edge non-manifold.
  EXPECT_FALSE(cube.IsWatertight());
  EXPECT_FALSE(TriangleMesh().IsWatertight());
}

TEST(TriangleMeshTest, VertexNormalsOfASpherePointOutwards) {
  TriangleMesh sphere = test::MakeUvSphere(20, 24, 48, {1, 2, 3});
  const std::vector<Eigen::Vector3f> analytic = sphere.normals;
  sphere.ComputeVertexNormals();
  ASSERT_EQ(sphere.normals.size(), analytic.size());
  for (size_t i = 0; i < analytic.size(); ++i) {
    EXPECT_NEAR(sphere.normals[i].norm(), 1.0f, 1e-5f);
    EXPECT_GT(sphere.normals[i].dot(analytic[i]), 0.995f) << "vertex " << i;
  }
}

TEST(TriangleMeshTest, CheckFindsBadIndicesCountsAndNonFiniteValues) {
  TriangleMesh mesh = test::MakeCube(1);
  EXPECT_NO_THROW(mesh.Check());
  mesh.faces[3][1] = 8;
  EXPECT_THROW(mesh.Check(), InputError);
  mesh = test::MakeCube(1);
  mesh.faces[3][1] = -1;
  EXPECT_THROW(mesh.Check(), InputError);
  mesh = test::MakeCube(1);
  mesh.colors.resize(7);
  EXPECT_THROW(mesh.Check(), InputError);
  mesh = test::MakeCube(1);
  mesh.vertices[2].y() = NAN;
  EXPECT_THROW(mesh.Check(), InputError);
  mesh = test::MakeCube(1);
  mesh.ComputeVertexNormals();
  mesh.normals[0].x() = INFINITY;
  EXPECT_THROW(mesh.Check(), InputError);
}

}  // namespace
}  // namespace ihs
