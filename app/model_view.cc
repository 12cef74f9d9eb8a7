#include "app/model_view.h"

#include <algorithm>
#include <cmath>

namespace ihs::app {
namespace {

constexpr double kDegreesPerDragPixel = 0.4;
// The fitted model's bounding sphere fills this share of the image's shorter half-angle.
constexpr double kFitShare = 0.9;

// The shade of a surface with unit `normal` (camera frame, toward the viewer: z < 0):
// ambient, a key light from the upper left in front, a light from the viewer.
float Diffuse(const Eigen::Vector3f& normal) {
  static const Eigen::Vector3f kKey = Eigen::Vector3f(-0.5f, -0.6f, -0.62f).normalized();
  return 0.15f + 0.55f * std::max(0.0f, normal.dot(kKey)) + 0.3f * std::max(0.0f, -normal.z());
}

// A Blinn highlight of the key light seen from the viewer.
float Highlight(const Eigen::Vector3f& normal) {
  static const Eigen::Vector3f kHalf =
      (Eigen::Vector3f(-0.5f, -0.6f, -0.62f).normalized() + Eigen::Vector3f(0, 0, -1)).normalized();
  return 0.3f * std::pow(std::max(0.0f, normal.dot(kHalf)), 24.0f);
}

}  // namespace

ModelViewpoint ModelViewpoint::Dragged(double dx, double dy) const {
  ModelViewpoint turned = *this;
  turned.yaw_deg = std::remainder(yaw_deg + kDegreesPerDragPixel * dx, 360.0);
  turned.pitch_deg = std::clamp(pitch_deg + kDegreesPerDragPixel * dy, -kMaxPitchDeg, kMaxPitchDeg);
  return turned;
}

RgbImage ShadeRaycast(const fusion::RaycastImage& cast) {
  RgbImage image{cast.width, cast.height, {}};
  image.rgb.assign(static_cast<std::size_t>(cast.width) * cast.height * 3, 0);
  for (std::size_t i = 0; i < cast.depth_mm.size(); ++i) {
    if (cast.depth_mm[i] <= 0) continue;
    Eigen::Vector3f normal = cast.normals[i];
    if (normal.z() > 0) normal = -normal;  // Toward the viewer.
    const float diffuse = Diffuse(normal), highlight = 255.0f * Highlight(normal);
    const bool colored = i < cast.colors.size();
    for (int c = 0; c < 3; ++c) {
      // Dark colours lifted toward grey so their shading still shows.
      const float base = colored ? 50.0f + 0.8f * cast.colors[i][c] : 200.0f;
      image.rgb[i * 3 + c] =
          static_cast<std::uint8_t>(std::min(255.0f, base * diffuse + highlight));
    }
  }
  return image;
}

ModelView ViewModelFromCamera(const fusion::TsdfVolume& volume, const CameraIntrinsics& intrinsics,
                              const Rigid3& cam_from_object) {
  fusion::RaycastImage cast = volume.Raycast(intrinsics, cam_from_object);
  ModelView view;
  view.image = ShadeRaycast(cast);
  view.depth_mm = std::move(cast.depth_mm);
  return view;
}

Rigid3 FittedViewPose(const Eigen::AlignedBox3f& box, const CameraIntrinsics& intrinsics,
                      const Rigid3& cam_from_object, const ModelViewpoint& viewpoint) {
  const Eigen::Vector3d centre = box.center().cast<double>();
  const double radius = std::max(1.0, 0.5 * static_cast<double>(box.diagonal().norm()));
  // The half-angle the image spans along its shorter side, from the principal point.
  const double half_angle =
      std::min({std::atan(intrinsics.cx / intrinsics.fx),
                std::atan((intrinsics.width - intrinsics.cx) / intrinsics.fx),
                std::atan(intrinsics.cy / intrinsics.fy),
                std::atan((intrinsics.height - intrinsics.cy) / intrinsics.fy)});
  const double distance = radius / std::sin(kFitShare * half_angle);
  // Camera frame: x right, y down. Yaw turns about y, pitch about x, both about the centre.
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(-viewpoint.yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(viewpoint.pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Matrix3d rotation = turn * cam_from_object.rotation();
  return Rigid3(rotation, Eigen::Vector3d(0, 0, distance) - rotation * centre);
}

RgbImage ViewModelFitted(const fusion::TsdfVolume& volume, const CameraIntrinsics& intrinsics,
                         const Rigid3& cam_from_object, const ModelViewpoint& viewpoint) {
  const Eigen::AlignedBox3f box = volume.ObservedBox();
  if (box.isEmpty()) {
    RgbImage black{intrinsics.width, intrinsics.height, {}};
    black.rgb.assign(static_cast<std::size_t>(intrinsics.width) * intrinsics.height * 3, 0);
    return black;
  }
  const Rigid3 pose = FittedViewPose(box, intrinsics, cam_from_object, viewpoint);
  return ShadeRaycast(volume.Raycast(intrinsics, pose));
}

}  // namespace ihs::app
