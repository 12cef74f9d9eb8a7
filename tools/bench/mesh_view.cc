#include "tools/bench/mesh_view.h"

#include <cmath>

#include "render/offscreen_renderer.h"

namespace ihs::bench {
namespace {

constexpr double kHalfFieldOfView = 0.35;  // rad, about 40° across.

CameraIntrinsics SquareCamera(int size) {
  CameraIntrinsics camera;
  camera.width = camera.height = size;
  camera.fx = camera.fy = 0.5 * size / std::tan(kHalfFieldOfView);
  camera.cx = camera.cy = 0.5 * (size - 1);
  return camera;
}

}  // namespace

MeshView::MeshView(int size) : size_(size) {
  render::RendererOptions options;
  options.background = {255, 255, 255};
  renderer_ = std::make_unique<render::OffscreenRenderer>(SquareCamera(size), options);
}

MeshView::~MeshView() = default;

std::vector<std::uint8_t> MeshView::Draw(const TriangleMesh& mesh, const Rigid3& truth_from_mesh,
                                         const Eigen::Vector3d& center, double radius_mm) {
  // Camera on a ray from the centre, 35° around the axis and 20° above the horizon, looking at
  // the centre: OpenCV axes (x right, y down, z forward), the object's +z up in the image.
  const double azimuth = 35.0 * M_PI / 180, elevation = 20.0 * M_PI / 180;
  const Eigen::Vector3d towards_camera(std::cos(elevation) * std::cos(azimuth),
                                       std::cos(elevation) * std::sin(azimuth),
                                       std::sin(elevation));
  const double distance = 1.08 * radius_mm / std::sin(kHalfFieldOfView);
  const Eigen::Vector3d eye = center + distance * towards_camera;
  const Eigen::Vector3d forward = -towards_camera;
  const Eigen::Vector3d down =
      (-Eigen::Vector3d::UnitZ() + forward.dot(Eigen::Vector3d::UnitZ()) * forward).normalized();
  const Eigen::Vector3d right = down.cross(forward);
  Eigen::Matrix3d cam_from_truth;
  cam_from_truth.row(0) = right;
  cam_from_truth.row(1) = down;
  cam_from_truth.row(2) = forward;
  const Rigid3 camera(cam_from_truth, -cam_from_truth * eye);
  render::RenderItem item;
  item.mesh = &mesh;
  item.cam_from_mesh = camera * truth_from_mesh;
  item.color = {190, 190, 190};
  return renderer_->Render({item}).rgb;
}

}  // namespace ihs::bench
