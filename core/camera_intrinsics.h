#pragma once
// Pinhole camera intrinsics, OpenCV convention: x right, y down, z forward, millimetres.

#include <Eigen/Core>

namespace ihs {

/// Pinhole intrinsics of an image of `width`×`height` pixels:
/// u = fx·X/Z + cx, v = fy·Y/Z + cy, with (X, Y, Z) in the camera frame (mm).
struct CameraIntrinsics {
  /// Focal length along x, pixels.
  double fx = 525.0;
  /// Focal length along y, pixels.
  double fy = 525.0;
  /// Principal point x, pixels (pixel centres at integer coordinates).
  double cx = 319.5;
  /// Principal point y, pixels.
  double cy = 239.5;
  /// Image width, pixels.
  int width = 640;
  /// Image height, pixels.
  int height = 480;

  /// The Carmine 1.09 at 640×480 as the paper's data used it: fx = fy = 525, c = (319.5, 239.5).
  static CameraIntrinsics Carmine109() { return CameraIntrinsics{}; }

  /// Intrinsics from horizontal and vertical fields of view (radians), as OpenNI2 reports them;
  /// principal point at the image centre; focal lengths rounded to 0.001 px.
  static CameraIntrinsics FromFieldOfView(int width, int height, double horizontal_fov_rad,
                                          double vertical_fov_rad);

  /// The same camera at another resolution (focal lengths and principal point scaled).
  CameraIntrinsics Scaled(int new_width, int new_height) const;

  /// Pixel coordinates (u, v) of a camera-frame point; `point_mm.z()` must be positive.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_mm) const {
    return {fx * point_mm.x() / point_mm.z() + cx, fy * point_mm.y() / point_mm.z() + cy};
  }

  /// Camera-frame point (mm) seen at pixel (u, v) at depth `depth_mm` along the optical axis.
  Eigen::Vector3d BackProject(double u, double v, double depth_mm) const {
    return {(u - cx) * depth_mm / fx, (v - cy) * depth_mm / fy, depth_mm};
  }

  /// Whether pixel coordinates (u, v) fall inside the image (pixel centres at integers).
  bool Contains(double u, double v) const {
    return u > -0.5 && v > -0.5 && u < width - 0.5 && v < height - 0.5;
  }

  /// Horizontal field of view, radians.
  double HorizontalFovRad() const;
  /// Vertical field of view, radians.
  double VerticalFovRad() const;

  /// Throws std::invalid_argument naming the bad field unless all fields are usable.
  void Check() const;
};

}  // namespace ihs
