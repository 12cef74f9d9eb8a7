#include "tools/bench/open3d_baseline.h"

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <open3d/pipelines/odometry/Odometry.h>
#include <open3d/utility/Logging.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/stopwatch.h"

namespace ihs::bench {

bool Open3dAvailable() { return true; }

struct Open3dBaseline::State {
  CameraIntrinsics intrinsics;
  Open3dBaselineOptions options;
  open3d::camera::PinholeCameraIntrinsic camera;
  open3d::pipelines::integration::ScalableTSDFVolume volume;
  open3d::pipelines::odometry::OdometryOption odometry_option;
  // The previous registered frame (intensity + depth, for the odometry) and its pose.
  std::shared_ptr<open3d::geometry::RGBDImage> previous;
  Eigen::Matrix4d object_from_camera = Eigen::Matrix4d::Identity();
  Open3dBaselineResult result;
  double odometry_ms = 0, integrate_ms = 0;
  int processed = 0;

  State(const CameraIntrinsics& in, const Open3dBaselineOptions& opt)
      : intrinsics(in),
        options(opt),
        camera(in.width, in.height, in.fx, in.fy, in.cx, in.cy),
        volume(opt.voxel_mm / 1000.0, opt.voxel_mm * opt.truncation_voxels / 1000.0,
               open3d::pipelines::integration::TSDFVolumeColorType::RGB8),
        odometry_option(opt.iterations, opt.max_depth_difference_mm / 1000.0, 0.0,
                        opt.max_depth_mm / 1000.0) {}
};

Open3dBaseline::Open3dBaseline(const CameraIntrinsics& intrinsics, Open3dBaselineOptions options)
    : state_(std::make_unique<State>(intrinsics, options)) {
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
}

Open3dBaseline::~Open3dBaseline() = default;

void Open3dBaseline::Process(const Frame& frame, const std::vector<std::uint8_t>& keep) {
  State& s = *state_;
  ++s.result.frames;
  const int n = frame.PixelCount();
  open3d::geometry::Image depth, color;
  depth.Prepare(frame.width, frame.height, 1, 2);
  color.Prepare(frame.width, frame.height, 3, 1);
  auto* d = depth.PointerAs<std::uint16_t>();
  int valid = 0;
  for (int i = 0; i < n; ++i) {
    const bool use = i < static_cast<int>(keep.size()) && keep[i] != 0;
    d[i] = use ? frame.depth_mm[i] : 0;
    valid += d[i] != 0;
  }
  if (frame.HasColor()) std::memcpy(color.data_.data(), frame.rgb.data(), frame.rgb.size());
  if (valid == 0) {
    ++s.result.empty_frames;
    return;
  }
  const double depth_scale = 1000.0, depth_trunc = s.options.max_depth_mm / 1000.0;
  auto gray = open3d::geometry::RGBDImage::CreateFromColorAndDepth(color, depth, depth_scale,
                                                                   depth_trunc, true);
  auto start = SteadyClock::now();
  if (s.previous) {
    // Odometry of the current frame (source) into the previous one (target): the transform
    // carries the current camera's points into the previous camera's frame. It starts from no
    // motion, as Open3D's reconstruction system does for adjacent frames: a constant-velocity
    // start lets one bad estimate derail every later one.
    const auto [success, previous_from_current, information] =
        open3d::pipelines::odometry::ComputeRGBDOdometry(
            *gray, *s.previous, s.camera, Eigen::Matrix4d::Identity(),
            open3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm(), s.odometry_option);
    (void)information;
    s.odometry_ms += MillisecondsSince(start);
    if (!success) {
      ++s.result.odometry_failures;
      ++s.processed;
      return;
    }
    s.object_from_camera = s.object_from_camera * previous_from_current;
  }
  s.previous = gray;
  start = SteadyClock::now();
  auto rgbd = open3d::geometry::RGBDImage::CreateFromColorAndDepth(color, depth, depth_scale,
                                                                   depth_trunc, false);
  const Eigen::Matrix4d camera_from_object = s.object_from_camera.inverse();
  s.volume.Integrate(*rgbd, s.camera, camera_from_object);
  s.integrate_ms += MillisecondsSince(start);
  ++s.processed;
  Eigen::Matrix4d mm = camera_from_object;
  mm.block<3, 1>(0, 3) *= 1000.0;
  s.result.trajectory.push_back({frame.depth_timestamp_us * 1e-6, Rigid3::FromMatrix(mm)});
}

Open3dBaselineResult Open3dBaseline::Finish() {
  State& s = *state_;
  Open3dBaselineResult result = s.result;
  result.odometry_ms = s.processed ? s.odometry_ms / s.processed : 0;
  result.integrate_ms = s.processed ? s.integrate_ms / s.processed : 0;
  const std::shared_ptr<open3d::geometry::TriangleMesh> mesh = s.volume.ExtractTriangleMesh();
  result.raw.vertices.reserve(mesh->vertices_.size());
  for (const Eigen::Vector3d& v : mesh->vertices_)
    result.raw.vertices.push_back((v * 1000.0).cast<float>());
  if (mesh->vertex_colors_.size() == mesh->vertices_.size()) {
    for (const Eigen::Vector3d& c : mesh->vertex_colors_) {
      TriangleMesh::Color rgb;
      for (int k = 0; k < 3; ++k)
        rgb[k] = static_cast<std::uint8_t>(std::lround(std::clamp(c[k], 0.0, 1.0) * 255));
      result.raw.colors.push_back(rgb);
    }
  }
  // Open3D's marching cubes winds faces counter-clockwise seen from outside, as ours does.
  for (const Eigen::Vector3i& f : mesh->triangles_) result.raw.faces.push_back({f[0], f[1], f[2]});
  return result;
}

}  // namespace ihs::bench
