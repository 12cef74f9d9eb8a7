#include "render/offscreen_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/mesh_fixtures.h"

namespace ihs::render {
namespace {

// Depth of the analytic sphere (centre c, radius r) along the ray of pixel (u, v), or 0.
double SphereDepth(const CameraIntrinsics& k, double u, double v, const Eigen::Vector3d& c,
                   double r) {
  const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);  // z = 1.
  // |t·ray − c|² = r²  →  a t² − 2 b t + (|c|² − r²) = 0; depth = t (ray has z = 1).
  const double a = ray.squaredNorm(), b = ray.dot(c), disc = b * b - a * (c.squaredNorm() - r * r);
  if (disc < 0) return 0;
  return (b - std::sqrt(disc)) / a;
}

TEST(OffscreenRendererTest, SphereDepthMatchesTheAnalyticSphere) {
  const CameraIntrinsics k;  // Carmine 640×480.
  const Eigen::Vector3d centre(20, -15, 600);
  const double radius = 35;  // The paper's Ø70 mm ball.
  const TriangleMesh sphere = test::MakeUvSphere(radius, 360, 720);
  OffscreenRenderer renderer(k);
  RenderItem item;
  item.mesh = &sphere;
  item.cam_from_mesh = Rigid3::Translation(centre);
  item.label = kObject;
  const RenderOutput out = renderer.Render({item});
  ASSERT_EQ(out.width, 640);
  const std::vector<std::uint16_t> sensor_depth = out.DepthMillimetres();
  int compared = 0, silhouette_mismatch = 0;
  double worst = 0, worst_interior = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const size_t i = static_cast<size_t>(v) * k.width + u;
      const double analytic = SphereDepth(k, u, v, centre, radius);
      const bool drawn = out.depth_mm[i] > 0;
      if (drawn != (analytic > 0)) {
        ++silhouette_mismatch;  // Pixels whose centre grazes the rim may go either way.
        continue;
      }
      if (!drawn) {
        EXPECT_EQ(out.labels[i], kBackground);
        continue;
      }
      EXPECT_EQ(out.labels[i], kObject);
      const double error = std::abs(out.depth_mm[i] - analytic);
      worst = std::max(worst, error);
      // Rounded to whole mm as a sensor delivers it: off by the rounding at most.
      EXPECT_LE(std::abs(sensor_depth[i] - analytic), 0.5 + worst + 1e-3) << u << "," << v;
      if (analytic < centre.z() - 0.3 * radius) worst_interior = std::max(worst_interior, error);
      ++compared;
    }
  }
  std::printf("sphere depth error: %.4f mm at worst, %.4f mm away from the rim, %d pixels\n", worst,
              worst_interior, compared);
  EXPECT_GT(compared, 2800);  // The disc: π·(35·525/600)² ≈ 2940 px.
  EXPECT_LT(worst, 0.5);      // Every valid pixel, rim included.
  EXPECT_LT(worst_interior, 0.05);
  EXPECT_LT(silhouette_mismatch, 60);  // A one-pixel ring at most: the disc's rim is ~280 px.
}

TEST(OffscreenRendererTest, NearerSurfaceWinsInDepthLabelsAndColour) {
  const CameraIntrinsics k = CameraIntrinsics().Scaled(160, 120);
  const TriangleMesh sphere = test::MakeUvSphere(40, 60, 120);
  const TriangleMesh cube = test::MakeCube(20);
  OffscreenRenderer renderer(k);
  RenderItem object{&sphere, Rigid3::Translation({0, 0, 600}), {0, 200, 0}, false, kObject};
  RenderItem hand{&cube, Rigid3::Translation({0, 0, 520}), {220, 150, 120}, false, kHand};
  const RenderOutput out = renderer.Render({object, hand});
  const size_t centre = static_cast<size_t>(60) * 160 + 80;  // Pixel (80, 60), near the axis.
  EXPECT_EQ(out.labels[centre], kHand);
  EXPECT_NEAR(out.depth_mm[centre], 510.0, 0.05);              // The cube's front face.
  EXPECT_GT(out.rgb[3 * centre], 150);                         // Skin-coloured, lit head-on.
  const size_t side = static_cast<size_t>(60) * 160 + 80 + 6;  // Beside the cube: the sphere.
  EXPECT_EQ(out.labels[side], kObject);
  EXPECT_GT(out.rgb[3 * side + 1], 100);
  EXPECT_EQ(out.rgb[3 * side], 0);
  EXPECT_EQ(out.labels[0], kBackground);
  EXPECT_EQ(out.depth_mm[0], 0.f);
  EXPECT_EQ(out.DepthMillimetres()[centre], 510);
}

}  // namespace
}  // namespace ihs::render
