#pragma once
// Synthetic RGB-D frames with known content for sensor and fusion tests.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"

namespace ihs::test {

/// A frame whose depth and colour are deterministic functions of (u, v, index): depth varies
/// smoothly over 400–2000 mm with a few invalid (0) pixels; timestamps 33 333 µs apart.
Frame MakePatternFrame(std::int64_t index, int width = 640, int height = 480);

/// `count` pattern frames with indices 0..count-1.
std::vector<Frame> MakePatternFrames(int count, int width = 640, int height = 480);

/// An ellipsoid with `semi_axes_mm` about its own frame's origin, seen exactly (depth rounded
/// to whole mm, as a sensor gives it) by a camera at `cam_from_object`: red where the object
/// frame's x > 0, green elsewhere; nothing else in the frame.
Frame RenderEllipsoid(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_object,
                      const Eigen::Vector3d& semi_axes_mm);

/// The exact depth (mm, camera z) of that ellipsoid along pixel (u, v)'s ray, or 0 on a miss.
double EllipsoidDepth(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_object,
                      const Eigen::Vector3d& semi_axes_mm, double u, double v);

/// Camera poses all around an object at the origin, `distance_mm` in front of the camera: eight
/// turns about the y axis at three tilts about x, plus straight from above and below (26 views).
std::vector<Rigid3> ViewsAround(double distance_mm);

}  // namespace ihs::test
