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
#include <stdexcept>

#include "core/stopwatch.h"
#include "tools/bench/open3d_tracker.h"

namespace ihs::bench {

bool Open3dAvailable() { return true; }

namespace {

// Frame-to-frame RGB-D odometry into the previous registered frame, and the scalable TSDF.
class FrameToFrameTracker : public Open3dTracker {
 public:
  FrameToFrameTracker(const CameraIntrinsics& in, const Open3dBaselineOptions& opt)
      : intrinsics_(in),
        options_(opt),
        camera_(in.width, in.height, in.fx, in.fy, in.cx, in.cy),
        volume_(opt.voxel_mm / 1000.0, opt.voxel_mm * opt.truncation_voxels / 1000.0,
                open3d::pipelines::integration::TSDFVolumeColorType::RGB8),
        odometry_option_(opt.iterations, opt.max_depth_difference_mm / 1000.0, 0.0,
                         opt.max_depth_mm / 1000.0) {}

  Open3dStep Track(const std::vector<std::uint16_t>& depth_mm,
                   const std::vector<std::uint8_t>& rgb) override {
    open3d::geometry::Image depth, color;
    depth.Prepare(intrinsics_.width, intrinsics_.height, 1, 2);
    color.Prepare(intrinsics_.width, intrinsics_.height, 3, 1);
    std::memcpy(depth.data_.data(), depth_mm.data(), depth.data_.size());
    std::memcpy(color.data_.data(), rgb.data(), color.data_.size());
    const double depth_scale = 1000.0, depth_trunc = options_.max_depth_mm / 1000.0;
    auto gray = open3d::geometry::RGBDImage::CreateFromColorAndDepth(color, depth, depth_scale,
                                                                     depth_trunc, true);
    Open3dStep step;
    auto start = SteadyClock::now();
    if (previous_) {
      // Odometry of the current frame (source) into the previous one (target): the transform
      // carries the current camera's points into the previous camera's frame. It starts from no
      // motion, as Open3D's reconstruction system does for adjacent frames: a constant-velocity
      // start lets one bad estimate derail every later one.
      const auto [success, previous_from_current, information] =
          open3d::pipelines::odometry::ComputeRGBDOdometry(
              *gray, *previous_, camera_, Eigen::Matrix4d::Identity(),
              open3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm(), odometry_option_);
      (void)information;
      step.odometry_ms = MillisecondsSince(start);
      if (!success) {
        step.tracked = false;
        return step;
      }
      object_from_camera_ = object_from_camera_ * previous_from_current;
    }
    previous_ = gray;
    start = SteadyClock::now();
    auto rgbd = open3d::geometry::RGBDImage::CreateFromColorAndDepth(color, depth, depth_scale,
                                                                     depth_trunc, false);
    volume_.Integrate(*rgbd, camera_, object_from_camera_.inverse());
    step.integrate_ms = MillisecondsSince(start);
    step.object_from_camera = object_from_camera_;
    return step;
  }

  open3d::geometry::TriangleMesh Mesh() override { return *volume_.ExtractTriangleMesh(); }

 private:
  CameraIntrinsics intrinsics_;
  Open3dBaselineOptions options_;
  open3d::camera::PinholeCameraIntrinsic camera_;
  open3d::pipelines::integration::ScalableTSDFVolume volume_;
  open3d::pipelines::odometry::OdometryOption odometry_option_;
  // The previous registered frame (intensity + depth, for the odometry) and its pose.
  std::shared_ptr<open3d::geometry::RGBDImage> previous_;
  Eigen::Matrix4d object_from_camera_ = Eigen::Matrix4d::Identity();
};

// Open3D's mesh (metres) in ours (mm), with its colours.
TriangleMesh FromOpen3d(const open3d::geometry::TriangleMesh& mesh) {
  TriangleMesh out;
  out.vertices.reserve(mesh.vertices_.size());
  for (const Eigen::Vector3d& v : mesh.vertices_)
    out.vertices.push_back((v * 1000.0).cast<float>());
  if (mesh.vertex_colors_.size() == mesh.vertices_.size()) {
    for (const Eigen::Vector3d& c : mesh.vertex_colors_) {
      TriangleMesh::Color rgb;
      for (int k = 0; k < 3; ++k)
        rgb[k] = static_cast<std::uint8_t>(std::lround(std::clamp(c[k], 0.0, 1.0) * 255));
      out.colors.push_back(rgb);
    }
  }
  // Open3D's marching cubes winds faces counter-clockwise seen from outside, as ours does.
  for (const Eigen::Vector3i& f : mesh.triangles_) out.faces.push_back({f[0], f[1], f[2]});
  return out;
}

}  // namespace

std::unique_ptr<Open3dTracker> MakeFrameToFrameTracker(const CameraIntrinsics& intrinsics,
                                                       const Open3dBaselineOptions& options) {
  return std::make_unique<FrameToFrameTracker>(intrinsics, options);
}

struct Open3dBaseline::State {
  std::unique_ptr<Open3dTracker> tracker;
  Open3dBaselineResult result;
  double odometry_ms = 0, integrate_ms = 0, raycast_ms = 0;
  int processed = 0;
};

Open3dBaseline::Open3dBaseline(const CameraIntrinsics& intrinsics, Open3dBaselineOptions options)
    : state_(std::make_unique<State>()) {
  if (!(options.voxel_mm > 0) || !(options.truncation_voxels > 0) ||
      !(options.model_truncation_voxels > 0) || !(options.max_depth_mm > 0) ||
      options.iterations.empty() || options.model_iterations < 1 ||
      !(options.model_sample_mm > 0) || !(options.model_max_distance_mm > 0) ||
      options.block_resolution < 1 || options.block_count < 1)
    throw std::invalid_argument("Open3D baseline: bad options (sizes must be positive)");
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  state_->tracker = options.tracking == Open3dTracking::kFrameToModel
                        ? MakeFrameToModelTracker(intrinsics, options)
                        : MakeFrameToFrameTracker(intrinsics, options);
}

Open3dBaseline::~Open3dBaseline() = default;

void Open3dBaseline::Process(const Frame& frame, const std::vector<std::uint8_t>& keep) {
  State& s = *state_;
  ++s.result.frames;
  const int n = frame.PixelCount();
  std::vector<std::uint16_t> depth(n, 0);
  int valid = 0;
  for (int i = 0; i < n; ++i) {
    const bool use = i < static_cast<int>(keep.size()) && keep[i] != 0;
    depth[i] = use ? frame.depth_mm[i] : 0;
    valid += depth[i] != 0;
  }
  if (valid == 0) {
    ++s.result.empty_frames;
    return;
  }
  const std::vector<std::uint8_t> rgb =
      frame.HasColor() ? frame.rgb : std::vector<std::uint8_t>(3 * n, 0);
  const Open3dStep step = s.tracker->Track(depth, rgb);
  s.odometry_ms += step.odometry_ms;
  s.integrate_ms += step.integrate_ms;
  s.raycast_ms += step.raycast_ms;
  ++s.processed;
  if (!step.tracked) {
    ++s.result.odometry_failures;
    return;
  }
  Eigen::Matrix4d cam_from_object_mm = step.object_from_camera.inverse();
  cam_from_object_mm.block<3, 1>(0, 3) *= 1000.0;
  s.result.trajectory.push_back(
      {frame.depth_timestamp_us * 1e-6, Rigid3::FromMatrix(cam_from_object_mm)});
}

Open3dBaselineResult Open3dBaseline::Finish() {
  State& s = *state_;
  Open3dBaselineResult result = s.result;
  if (s.processed) {
    result.odometry_ms = s.odometry_ms / s.processed;
    result.integrate_ms = s.integrate_ms / s.processed;
    result.raycast_ms = s.raycast_ms / s.processed;
  }
  result.raw = FromOpen3d(s.tracker->Mesh());
  return result;
}

}  // namespace ihs::bench
