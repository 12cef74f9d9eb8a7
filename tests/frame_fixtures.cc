#include "tests/frame_fixtures.h"

#include <cmath>

namespace ihs::test {

Frame MakePatternFrame(std::int64_t index, int width, int height) {
  Frame frame = Frame::Blank(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const int i = v * width + u;
      const bool hole = (u * 7 + v * 13 + index) % 29 == 0;
      frame.depth_mm[i] =
          hole ? 0 : static_cast<std::uint16_t>(400 + (u * 3 + v * 2 + index * 5) % 1600);
      frame.rgb[3 * i + 0] = static_cast<std::uint8_t>(u + index);
      frame.rgb[3 * i + 1] = static_cast<std::uint8_t>(v * 2);
      frame.rgb[3 * i + 2] = static_cast<std::uint8_t>((u ^ v) + 3 * index);
    }
  }
  frame.index = index;
  frame.depth_timestamp_us = 1'000'000 + index * 33'333;
  frame.color_timestamp_us = frame.depth_timestamp_us + 1'000;
  return frame;
}

std::vector<Frame> MakePatternFrames(int count, int width, int height) {
  std::vector<Frame> frames;
  for (int i = 0; i < count; ++i) frames.push_back(MakePatternFrame(i, width, height));
  return frames;
}

namespace {
// The ray parameter (camera frame, unit ray) where pixel (u, v)'s ray first meets the ellipsoid,
// or a negative value on a miss. The caller inverts the pose once per frame (per pixel, it was
// most of the AddressSanitizer stage's fusion tests).
double EllipsoidHit(const CameraIntrinsics& intrinsics, const Rigid3& object_from_cam,
                    const Eigen::Vector3d& semi_axes_mm, double u, double v,
                    Eigen::Vector3d* ray_out) {
  const Eigen::Vector3d ray = intrinsics.BackProject(u, v, 1.0).normalized();
  // In the frame where the ellipsoid is the unit sphere.
  const Eigen::Vector3d origin = object_from_cam.translation().cwiseQuotient(semi_axes_mm);
  const Eigen::Vector3d direction = object_from_cam.RotateVector(ray).cwiseQuotient(semi_axes_mm);
  const double a = direction.squaredNorm(), b = origin.dot(direction), c = origin.squaredNorm() - 1;
  const double discriminant = b * b - a * c;
  if (ray_out) *ray_out = ray;
  if (discriminant < 0) return -1;
  return (-b - std::sqrt(discriminant)) / a;
}
}  // namespace

double EllipsoidDepth(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_object,
                      const Eigen::Vector3d& semi_axes_mm, double u, double v) {
  Eigen::Vector3d ray;
  const double t = EllipsoidHit(intrinsics, cam_from_object.Inverse(), semi_axes_mm, u, v, &ray);
  return t > 0 ? t * ray.z() : 0.0;
}

Frame RenderEllipsoid(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_object,
                      const Eigen::Vector3d& semi_axes_mm) {
  Frame frame = Frame::Blank(intrinsics.width, intrinsics.height, true);
  const Rigid3 object_from_cam = cam_from_object.Inverse();
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      Eigen::Vector3d ray;
      const double t = EllipsoidHit(intrinsics, object_from_cam, semi_axes_mm, u, v, &ray);
      if (t <= 0) continue;
      const int pixel = v * frame.width + u;
      frame.depth_mm[pixel] = static_cast<std::uint16_t>(std::lround(t * ray.z()));
      const bool red = (object_from_cam * Eigen::Vector3d(t * ray)).x() > 0;
      frame.rgb[3 * pixel] = red ? 220 : 30;
      frame.rgb[3 * pixel + 1] = red ? 30 : 200;
      frame.rgb[3 * pixel + 2] = 40;
    }
  }
  return frame;
}

std::vector<Rigid3> ViewsAround(double distance_mm) {
  const Rigid3 away = Rigid3::Translation({0, 0, distance_mm});
  std::vector<Rigid3> views;
  for (int a = 0; a < 8; ++a) {
    for (double tilt : {-0.9, 0.0, 0.9}) {
      views.push_back(away * Rigid3::FromAxisAngle({1, 0, 0}, tilt) *
                      Rigid3::FromAxisAngle({0, 1, 0}, a * M_PI / 4));
    }
  }
  views.push_back(away * Rigid3::FromAxisAngle({1, 0, 0}, M_PI / 2));
  views.push_back(away * Rigid3::FromAxisAngle({1, 0, 0}, -M_PI / 2));
  return views;
}

}  // namespace ihs::test
