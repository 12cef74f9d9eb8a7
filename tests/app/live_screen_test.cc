// What the live window shows: the model fitted to its panel and turned as dragged, lit; the
// screen's labels and state colours; the screen composed off-screen.

#include "app/live_screen.h"

#include <gtest/gtest.h>

#include <cmath>

#include "app/model_view.h"
#include "fusion/tsdf_volume.h"
#include "tests/frame_fixtures.h"

namespace ihs::app {
namespace {

const CameraIntrinsics kCamera = CameraIntrinsics::Carmine109();

// The object's centre projects to the principal point, every corner of its box lies in the
// image, and an unturned view looks from the camera's direction.
TEST(ModelViewTest, TheFittedViewCentresTheWholeBox) {
  const Eigen::AlignedBox3f box(Eigen::Vector3f(-40, -25, -60), Eigen::Vector3f(20, 35, 50));
  const Rigid3 cam_from_object =
      Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, 1, -0.2), 1.1, Eigen::Vector3d(30, -20, 700));
  for (const ModelViewpoint viewpoint : {ModelViewpoint{}, ModelViewpoint{120, -40}}) {
    const Rigid3 pose = FittedViewPose(box, kCamera, cam_from_object, viewpoint);
    const Eigen::Vector2d centre =
        kCamera.Project(pose * Eigen::Vector3d(box.center().cast<double>()));
    EXPECT_NEAR(centre.x(), kCamera.cx, 1e-6);
    EXPECT_NEAR(centre.y(), kCamera.cy, 1e-6);
    double widest = 0;  // The corners' largest offset from the centre, pixels.
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d corner_mm =
          box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).cast<double>();
      const Eigen::Vector3d at = pose * corner_mm;
      ASSERT_GT(at.z(), 0);
      const Eigen::Vector2d pixel = kCamera.Project(at);
      EXPECT_TRUE(kCamera.Contains(pixel.x(), pixel.y())) << pixel.transpose();
      widest = std::max(widest, (pixel - centre).norm());
    }
    EXPECT_GT(widest, 0.3 * kCamera.height) << "fitted, not a speck";
  }
  const Rigid3 straight = FittedViewPose(box, kCamera, cam_from_object, {});
  EXPECT_LT(straight.RotationAngleToRad(cam_from_object), 1e-9);
}

// Dragging right brings the model's front to the right and its left side to the viewer;
// dragging down tips the front down; pitch stops short of the pole.
TEST(ModelViewTest, ADragTurnsTheModelTheWayTheMouseMoves) {
  const Eigen::AlignedBox3f box(Eigen::Vector3f::Constant(-30), Eigen::Vector3f::Constant(30));
  const Rigid3 camera = Rigid3::Translation(Eigen::Vector3d(0, 0, 500));
  const Eigen::Vector3d front(0, 0, -30);  // The point facing the camera.
  const ModelViewpoint right = ModelViewpoint{}.Dragged(50, 0);
  EXPECT_NEAR(right.yaw_deg, 20, 1e-9);
  EXPECT_GT(kCamera.Project(FittedViewPose(box, kCamera, camera, right) * front).x(),
            kCamera.cx + 20);
  const ModelViewpoint down = ModelViewpoint{}.Dragged(0, 50);
  EXPECT_GT(kCamera.Project(FittedViewPose(box, kCamera, camera, down) * front).y(),
            kCamera.cy + 20);
  EXPECT_EQ(ModelViewpoint{}.Dragged(0, 1e4).pitch_deg, ModelViewpoint::kMaxPitchDeg);
  EXPECT_NEAR(ModelViewpoint{}.Dragged(900, 0).yaw_deg, 0, 1e-9);  // 360° round.
}

// A ball fused from all around (red where x > 0, green elsewhere): seen from the camera the
// red half is on the right; turned 90° to the right its green side faces the viewer.
TEST(ModelViewTest, TheTurnedModelShowsItsOtherSide) {
  fusion::TsdfOptions options;
  options.resolution = 128;
  fusion::TsdfVolume volume(options);
  EXPECT_TRUE(ViewModelFitted(volume, kCamera, Rigid3(), {}).rgb ==
              std::vector<std::uint8_t>(kCamera.width * kCamera.height * 3, 0));
  const Eigen::Vector3d ball = Eigen::Vector3d::Constant(40);
  for (const Rigid3& view : test::ViewsAround(600)) {
    volume.Integrate(test::RenderEllipsoid(kCamera, view, ball), {}, kCamera, view);
  }
  const Rigid3 camera = Rigid3::Translation(Eigen::Vector3d(0, 0, 600));
  auto colour = [](const RgbImage& image, int u, int v) {
    const std::uint8_t* p = &image.rgb[(v * image.width + u) * 3];
    return Eigen::Vector3i(p[0], p[1], p[2]);
  };
  const RgbImage straight = ViewModelFitted(volume, kCamera, camera, {});
  const int u = static_cast<int>(kCamera.cx), v = static_cast<int>(kCamera.cy);
  EXPECT_GT(colour(straight, u + 60, v).x(), colour(straight, u + 60, v).y() + 40);  // Red.
  EXPECT_GT(colour(straight, u - 60, v).y(), colour(straight, u - 60, v).x() + 40);  // Green.
  const RgbImage turned = ViewModelFitted(volume, kCamera, camera, {90, 0});
  EXPECT_GT(colour(turned, u, v).y(), colour(turned, u, v).x() + 40);
  EXPECT_EQ(colour(turned, 2, 2), Eigen::Vector3i::Zero());  // No model: black.
}

// Lit so the shape reads: a surface facing the key light (upper left) is brighter than one
// turned from it, dark colours still show their shading, misses stay black.
TEST(ModelViewTest, ShadingFollowsTheLight) {
  fusion::RaycastImage cast;
  cast.width = 4, cast.height = 1;
  cast.depth_mm = {500, 500, 500, 0};
  cast.normals = {Eigen::Vector3f(-0.5f, -0.5f, -0.7f).normalized(),
                  Eigen::Vector3f(0.5f, 0.5f, -0.7f).normalized(), Eigen::Vector3f(0, 0, -1),
                  Eigen::Vector3f(0, 0, -1)};
  cast.colors = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  const RgbImage image = ShadeRaycast(cast);
  EXPECT_GT(image.rgb[0], image.rgb[3] + 30);  // Toward the key light vs away from it.
  EXPECT_GT(image.rgb[3], 0);                  // Black colour, still visible.
  EXPECT_EQ(image.rgb[9], 0);                  // A miss.
}

// The screen: both panels labelled (a darkened strip along their tops), the states coloured
// by how they stand, the model panel saying it waits for the model before there is one.
TEST(LiveScreenTest, LabelsAndStatesAreDrawn) {
  LiveView view;  // No frame and no model yet.
  PipelineProgress progress;
  progress.hand = "tracked";
  progress.object = "lost";
  progress.coverage = 0.63;
  const RgbImage screen = ComposeLiveScreen(view, kCamera, progress);
  int width = 0, height = 0;
  LiveScreenSize(kCamera, &width, &height);
  ASSERT_EQ(screen.width, width);
  ASSERT_EQ(screen.height, height);
  ASSERT_EQ(screen.width, 2 * kCamera.width);
  ASSERT_GT(screen.height, kCamera.height);
  auto count = [&](int v0, int v1, int u0, int u1, auto&& pick) {
    int n = 0;
    for (int v = v0; v < v1; ++v) {
      for (int u = u0; u < u1; ++u) n += pick(&screen.rgb[(v * screen.width + u) * 3]);
    }
    return n;
  };
  auto bright = [](const std::uint8_t* p) { return p[0] > 200 && p[1] > 200 && p[2] > 200; };
  auto green = [](const std::uint8_t* p) { return p[1] > 180 && p[0] < 150 && p[2] < 150; };
  auto red = [](const std::uint8_t* p) { return p[0] > 200 && p[1] < 140 && p[2] < 140; };
  const int w = kCamera.width, h = kCamera.height;
  EXPECT_GT(count(0, 24, 0, w, bright), 100) << "the camera panel's label";
  EXPECT_GT(count(0, 24, w, 2 * w, bright), 100) << "the model panel's label";
  EXPECT_GT(count(h / 2 - 20, h / 2 + 10, w, 2 * w, bright), 100) << "waiting for the model";
  EXPECT_GT(count(h, h + 26, 0, 2 * w, green), 20) << "hand: tracked, in green";
  EXPECT_GT(count(h, h + 26, 0, 2 * w, red), 20) << "object: lost, in red";
  progress.object = "registered";
  const RgbImage well = ComposeLiveScreen(view, kCamera, progress);
  int red_left = 0;
  for (int v = h; v < h + 26; ++v) {
    for (int u = 0; u < 2 * w; ++u) red_left += red(&well.rgb[(v * well.width + u) * 3]);
  }
  EXPECT_EQ(red_left, 0);
  EXPECT_EQ(StatusLine(progress),
            "hand: tracked | object: registered | seen 63 % | 0.0 fps | frames 0, fused 0, "
            "dropped 0");
}

}  // namespace
}  // namespace ihs::app
