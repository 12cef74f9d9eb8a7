#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "tests/mesh_fixtures.h"
#include "tests/test_util.h"
#include "tools/synth/sensor_model.h"

namespace ihs::synth {
namespace {

// A flat, grey, camera-facing wall at `z_mm` filling the image (a rendering without a renderer).
render::RenderOutput Wall(const CameraIntrinsics& k, double z_mm) {
  render::RenderOutput out;
  out.width = k.width;
  out.height = k.height;
  out.depth_mm.assign(static_cast<size_t>(k.width) * k.height, static_cast<float>(z_mm));
  out.rgb.assign(out.depth_mm.size() * 3, 128);
  out.labels.assign(out.depth_mm.size(), render::kObject);
  return out;
}

TEST(SensorModelTest, IdealModelOnlyRoundsToMillimetres) {
  const CameraIntrinsics k = CameraIntrinsics().Scaled(64, 48);
  std::mt19937 rng = test::Rng(1);
  const Frame frame = ApplySensorModel(Wall(k, 600.4), k, SensorModelOptions::Ideal(), rng);
  for (std::uint16_t d : frame.depth_mm) ASSERT_EQ(d, 600);
  for (std::uint8_t c : frame.rgb) ASSERT_EQ(c, 128);
}

TEST(SensorModelTest, DepthNoiseGrowsWithTheSquareOfDistance) {
  const CameraIntrinsics k = CameraIntrinsics().Scaled(160, 120);
  SensorModelOptions options = SensorModelOptions::Ideal();
  options.depth_noise = true;
  for (const double z : {600.0, 1200.0}) {
    std::mt19937 rng = test::Rng(2);
    // Rounding to mm adds 1/12 mm² of variance; remove it from the estimate.
    const Frame frame = ApplySensorModel(Wall(k, z), k, options, rng);
    double sum = 0, sum2 = 0;
    for (std::uint16_t d : frame.depth_mm) {
      sum += d;
      sum2 += double(d) * d;
    }
    const double n = frame.depth_mm.size(), mean = sum / n;
    const double sigma = std::sqrt(std::max(0.0, sum2 / n - mean * mean - 1.0 / 12));
    const double expected = 1.425e-6 * z * z;  // 0.51 mm at 0.6 m, 2.05 mm at 1.2 m.
    EXPECT_NEAR(sigma / expected, 1.0, 0.08) << z;
    EXPECT_NEAR(mean, z, 0.1) << z;
  }
}

TEST(SensorModelTest, QuantisationStepsFollowTheDisparity) {
  const CameraIntrinsics k{525, 525, 31.5, 23.5, 64, 48};  // The Carmine's focal length.
  SensorModelOptions options = SensorModelOptions::Ideal();
  options.quantization = true;
  // Walls from 590 to 610 mm in 0.1 mm steps land on discrete depths z²/(f·b)/8 ≈ 1.14 mm apart.
  std::set<std::uint16_t> levels;
  for (double z = 590; z <= 610; z += 0.1) {
    std::mt19937 rng = test::Rng(3);
    levels.insert(ApplySensorModel(Wall(k, z), k, options, rng).depth_mm[0]);
  }
  const double step = 600.0 * 600.0 / (k.fx * 75.0) / 8;
  EXPECT_NEAR(static_cast<double>(levels.size()), 20.0 / step + 1, 2.0);  // About 18.
  EXPECT_GE(levels.size(), 15u);
}

TEST(SensorModelTest, SilhouettesLoseOrSmearPixelsAndTiltedSurfacesDropOut) {
  const CameraIntrinsics k = CameraIntrinsics().Scaled(160, 120);
  render::OffscreenRenderer renderer(k);
  const TriangleMesh sphere = test::MakeUvSphere(35, 60, 120);
  const render::RenderOutput rendering = renderer.Render(
      {{&sphere, Rigid3::Translation({0, 0, 400}), {200, 200, 200}, false, render::kObject}});
  std::mt19937 rng = test::Rng(4);
  const Frame frame = ApplySensorModel(rendering, k, SensorModelOptions{}, rng);
  int rendered = 0, kept = 0;
  for (size_t i = 0; i < frame.depth_mm.size(); ++i) {
    rendered += rendering.depth_mm[i] > 0;
    kept += frame.depth_mm[i] > 0;
  }
  EXPECT_LT(kept, rendered);           // The rim and the grazing band are lost…
  EXPECT_GT(kept, rendered * 8 / 10);  // …but most of the sphere is seen,
  const double radius_px = 35 * k.fx / 400;
  for (int v = 0; v < k.height; ++v) {  // …and all of its centre, which faces the camera.
    for (int u = 0; u < k.width; ++u) {
      if (std::hypot(u - k.cx, v - k.cy) < 0.6 * radius_px) {
        EXPECT_GT(frame.DepthAt(u, v), 360) << u << "," << v;
      }
    }
  }
  // Same seed, same frame: the generator is deterministic.
  std::mt19937 again = test::Rng(4);
  const Frame repeat = ApplySensorModel(rendering, k, SensorModelOptions{}, again);
  EXPECT_EQ(repeat.depth_mm, frame.depth_mm);
  EXPECT_EQ(repeat.rgb, frame.rgb);
}

}  // namespace
}  // namespace ihs::synth
