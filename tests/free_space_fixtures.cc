#include "tests/free_space_fixtures.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ihs::test {

RenderedView CubeView(const CameraIntrinsics& camera, const Rigid3& cam_from_cube) {
  RenderedView view;
  view.frame = Frame::Blank(camera.width, camera.height, false);
  view.object_box = {camera.width, camera.height, 0, 0};
  const Rigid3 cube_from_cam = cam_from_cube.Inverse();
  const Eigen::Vector3d origin = cube_from_cam.translation();
  const double half = kCubeEdgeMm / 2.0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      // The ray in the cube's frame, slab test.
      const Eigen::Vector3d direction = cube_from_cam.RotateVector(camera.BackProject(u, v, 1.0));
      double enter = 0, leave = std::numeric_limits<double>::infinity();
      for (int axis = 0; axis < 3; ++axis) {
        const double a = (-half - origin[axis]) / direction[axis];
        const double b = (half - origin[axis]) / direction[axis];
        enter = std::max(enter, std::min(a, b));
        leave = std::min(leave, std::max(a, b));
      }
      if (enter > leave) continue;
      // `direction` has unit depth along the camera's axis: the parameter is the depth.
      view.frame.depth_mm[v * camera.width + u] = static_cast<std::uint16_t>(std::lround(enter));
      view.object_box = {std::min(view.object_box[0], u), std::min(view.object_box[1], v),
                         std::max(view.object_box[2], u + 1), std::max(view.object_box[3], v + 1)};
    }
  }
  return view;
}

}  // namespace ihs::test
