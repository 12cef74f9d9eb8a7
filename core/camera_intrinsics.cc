#include "core/camera_intrinsics.h"

#include <cmath>

#include "core/check.h"

namespace ihs {

CameraIntrinsics CameraIntrinsics::FromFieldOfView(int width, int height, double horizontal_fov_rad,
                                                   double vertical_fov_rad) {
  IHS_CHECK_ARG(width > 0 && height > 0,
                "image size must be positive, got " << width << "x" << height);
  IHS_CHECK_ARG(horizontal_fov_rad > 0 && horizontal_fov_rad < M_PI,
                "horizontal field of view must be in (0, pi) rad, got " << horizontal_fov_rad);
  IHS_CHECK_ARG(vertical_fov_rad > 0 && vertical_fov_rad < M_PI,
                "vertical field of view must be in (0, pi) rad, got " << vertical_fov_rad);
  CameraIntrinsics intrinsics;
  intrinsics.width = width;
  intrinsics.height = height;
  // Rounded to 0.001 px: .oni files store the field of view as a 32-bit float, whose rounding
  // moves the focal length by ~1e-5 px; rounded, the same camera gives the same intrinsics from
  // an .oni file as from a TUM folder's text (and the same scan), far below any calibration's
  // precision.
  auto round = [](double pixels) { return std::round(pixels * 1000.0) / 1000.0; };
  intrinsics.fx = round(width / (2.0 * std::tan(horizontal_fov_rad / 2.0)));
  intrinsics.fy = round(height / (2.0 * std::tan(vertical_fov_rad / 2.0)));
  intrinsics.cx = (width - 1) / 2.0;
  intrinsics.cy = (height - 1) / 2.0;
  return intrinsics;
}

CameraIntrinsics CameraIntrinsics::Scaled(int new_width, int new_height) const {
  IHS_CHECK_ARG(new_width > 0 && new_height > 0,
                "image size must be positive, got " << new_width << "x" << new_height);
  const double sx = static_cast<double>(new_width) / width;
  const double sy = static_cast<double>(new_height) / height;
  CameraIntrinsics scaled = *this;
  scaled.width = new_width;
  scaled.height = new_height;
  scaled.fx = fx * sx;
  scaled.fy = fy * sy;
  // Pixel centres sit at integers, so the image edge is at -0.5 and scales about that.
  scaled.cx = (cx + 0.5) * sx - 0.5;
  scaled.cy = (cy + 0.5) * sy - 0.5;
  return scaled;
}

double CameraIntrinsics::HorizontalFovRad() const { return 2.0 * std::atan(width / (2.0 * fx)); }

double CameraIntrinsics::VerticalFovRad() const { return 2.0 * std::atan(height / (2.0 * fy)); }

void CameraIntrinsics::Check() const {
  IHS_CHECK_ARG(std::isfinite(fx) && fx > 0, "intrinsics.fx must be positive, got " << fx);
  IHS_CHECK_ARG(std::isfinite(fy) && fy > 0, "intrinsics.fy must be positive, got " << fy);
  IHS_CHECK_ARG(std::isfinite(cx), "intrinsics.cx must be finite");
  IHS_CHECK_ARG(std::isfinite(cy), "intrinsics.cy must be finite");
  IHS_CHECK_ARG(width > 0, "intrinsics.width must be positive, got " << width);
  IHS_CHECK_ARG(height > 0, "intrinsics.height must be positive, got " << height);
}

}  // namespace ihs
