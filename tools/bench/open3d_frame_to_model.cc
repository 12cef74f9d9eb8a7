// Open3D's frame-to-model tracking against its own TSDF, KinectFusion's loop: Open3D's voxel-block
// TSDF (t::geometry::VoxelBlockGrid, as its dense SLAM's model keeps it) raycast at the last pose,
// the new frame aligned to that view by Open3D's point-to-plane ICP
// (pipelines::registration::RegistrationICP), then integrated at the pose found.
//
// Open3D's own t::pipelines::slam::Model::TrackFrameToModel cannot run on Debian's build: its
// projective ICP smooths the model's depth with a bilateral filter that Open3D implements on the
// CPU only with Intel IPP, which Debian's package lacks ("FilterBilateral ... not implemented").
//
// Two half-cell offsets of Open3D 0.16 are undone, as they would make any frame-to-model loop
// creep: its integration projects a voxel to the pixel below it (it truncates the image
// coordinates), and its raycast reads, for a point on the ray, the voxel below it (it floors the
// grid coordinates) whose value was integrated at the voxel's corner, which moves the surface
// half a voxel along each axis. Integrating with the principal point half a pixel on and
// raycasting with the grid half a voxel back make both read the nearest cell. Measured on a
// turning box (Open3dBaselineTest): without them the box's centre drifts 7 mm in 20 frames, with
// them it stays within 0.2 mm.
#include <open3d/core/EigenConverter.h>
#include <open3d/core/Tensor.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/t/geometry/Image.h>
#include <open3d/t/geometry/TriangleMesh.h>
#include <open3d/t/geometry/VoxelBlockGrid.h>

#include <algorithm>

#include "core/stopwatch.h"
#include "tools/bench/open3d_tracker.h"

namespace ihs::bench {
namespace {

namespace core = open3d::core;
namespace registration = open3d::pipelines::registration;

// Open3D's 3 × 3 camera matrix, the principal point moved by `offset` pixels.
core::Tensor Intrinsic(const CameraIntrinsics& in, double offset = 0) {
  return core::Tensor::Init<double>(
      {{in.fx, 0, in.cx + offset}, {0, in.fy, in.cy + offset}, {0, 0, 1}});
}

core::Tensor ToTensor(const Eigen::Matrix4d& matrix) {
  return core::eigen_converter::EigenMatrixToTensor(matrix);
}

class FrameToModelTracker : public Open3dTracker {
 public:
  FrameToModelTracker(const CameraIntrinsics& in, const Open3dBaselineOptions& opt)
      : intrinsics_(in),
        options_(opt),
        intrinsic_(Intrinsic(in)),
        integrate_intrinsic_(Intrinsic(in, 0.5)),
        // The voxels of Open3D's dense SLAM model: signed distance, weight, colour.
        grid_({"tsdf", "weight", "color"}, {core::Float32, core::UInt16, core::UInt16},
              {{1}, {1}, {3}}, static_cast<float>(opt.voxel_mm / 1000), opt.block_resolution,
              opt.block_count, cpu_) {}

  Open3dStep Track(const std::vector<std::uint16_t>& depth_mm,
                   const std::vector<std::uint8_t>& rgb) override {
    Open3dStep step;
    auto start = SteadyClock::now();
    if (integrated_ > 0) {
      step.tracked = Align(FramePoints(depth_mm));
      step.odometry_ms = MillisecondsSince(start);
    }
    const Eigen::Matrix4d camera_from_object = object_from_camera_.inverse();
    if (step.tracked) {
      start = SteadyClock::now();
      Integrate(depth_mm, rgb, ToTensor(camera_from_object));
      step.integrate_ms = MillisecondsSince(start);
    }
    start = SteadyClock::now();
    target_ = ModelPoints(camera_from_object);
    step.raycast_ms = MillisecondsSince(start);
    step.object_from_camera = object_from_camera_;
    return step;
  }

  open3d::geometry::TriangleMesh Mesh() override {
    if (integrated_ == 0) return {};
    return grid_.ExtractTriangleMesh(static_cast<float>(options_.weight_threshold)).ToLegacy();
  }

 private:
  float DepthMax() const { return static_cast<float>(options_.max_depth_mm / 1000); }
  float Truncation() const { return static_cast<float>(options_.model_truncation_voxels); }

  // The new frame (source) against the model's view at the last pose (target): the transform
  // carries the new camera's points into the last camera's frame. False when it fails Open3D's
  // checks (the pose is kept).
  bool Align(const std::shared_ptr<open3d::geometry::PointCloud>& source) {
    if (source->IsEmpty() || target_->IsEmpty()) return false;
    const auto result = registration::RegistrationICP(
        *source, *target_, options_.model_max_distance_mm / 1000, Eigen::Matrix4d::Identity(),
        registration::TransformationEstimationPointToPlane(),
        registration::ICPConvergenceCriteria(1e-6, 1e-6, options_.model_iterations));
    const double step_mm = 1000 * result.transformation_.block<3, 1>(0, 3).norm();
    if (result.fitness_ < options_.min_fitness || !(step_mm < options_.max_step_mm)) return false;
    object_from_camera_ = object_from_camera_ * result.transformation_;
    return true;
  }

  void Integrate(const std::vector<std::uint16_t>& depth_mm, const std::vector<std::uint8_t>& rgb,
                 const core::Tensor& extrinsic) {
    const int h = intrinsics_.height, w = intrinsics_.width;
    const open3d::t::geometry::Image depth(core::Tensor(depth_mm, {h, w, 1}, core::UInt16, cpu_));
    const open3d::t::geometry::Image color(core::Tensor(rgb, {h, w, 3}, core::UInt8, cpu_));
    frustum_ = grid_.GetUniqueBlockCoordinates(depth, integrate_intrinsic_, extrinsic, 1000,
                                               DepthMax(), Truncation());
    grid_.Integrate(frustum_, depth, color, integrate_intrinsic_, extrinsic, 1000, DepthMax(),
                    Truncation());
    ++integrated_;
  }

  // The frame's points (camera frame, metres), thinned to one per ICP sample cell.
  std::shared_ptr<open3d::geometry::PointCloud> FramePoints(
      const std::vector<std::uint16_t>& depth_mm) const {
    open3d::geometry::PointCloud cloud;
    for (int v = 0; v < intrinsics_.height; ++v) {
      for (int u = 0; u < intrinsics_.width; ++u) {
        const double z = depth_mm[v * intrinsics_.width + u] / 1000.0;
        if (z <= 0 || z > DepthMax()) continue;
        cloud.points_.emplace_back((u - intrinsics_.cx) * z / intrinsics_.fx,
                                   (v - intrinsics_.cy) * z / intrinsics_.fy, z);
      }
    }
    return cloud.VoxelDownSample(options_.model_sample_mm / 1000);
  }

  // The model's surface seen from `camera_from_object`, raycast in the blocks of the last
  // integrated frame: points and normals in that camera's frame, thinned as the frame's. Voxels
  // integrated fewer times than min(frames, 3) are left out (Open3D's dense SLAM's rule).
  std::shared_ptr<open3d::geometry::PointCloud> ModelPoints(
      const Eigen::Matrix4d& camera_from_object) {
    // The grid half a voxel back: the raycast then reads the nearest voxel (see the top).
    Eigen::Matrix4d half_voxel_back = Eigen::Matrix4d::Identity();
    half_voxel_back.block<3, 1>(0, 3).setConstant(-0.5 * options_.voxel_mm / 1000);
    const float weight = std::min(static_cast<float>(integrated_), 3.0f);
    auto maps = grid_.RayCast(frustum_, intrinsic_, ToTensor(camera_from_object * half_voxel_back),
                              intrinsics_.width, intrinsics_.height, {"vertex", "normal"}, 1000,
                              0.1f, DepthMax(), weight, Truncation());
    const core::Tensor vertex = maps["vertex"].Contiguous(), normal = maps["normal"].Contiguous();
    const float* p = vertex.GetDataPtr<float>();
    const float* n = normal.GetDataPtr<float>();
    open3d::geometry::PointCloud cloud;
    for (int64_t i = 0; i < vertex.NumElements() / 3; ++i) {
      const Eigen::Vector3d point(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      const Eigen::Vector3d direction(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
      if (!(point.z() > 0) || !(direction.norm() > 0.5)) continue;
      cloud.points_.push_back(point);
      cloud.normals_.push_back(direction.normalized());
    }
    return cloud.VoxelDownSample(options_.model_sample_mm / 1000);
  }

  const core::Device cpu_{"CPU:0"};
  CameraIntrinsics intrinsics_;
  Open3dBaselineOptions options_;
  core::Tensor intrinsic_, integrate_intrinsic_;
  open3d::t::geometry::VoxelBlockGrid grid_;
  core::Tensor frustum_;  // The blocks the last integrated frame touched.
  std::shared_ptr<open3d::geometry::PointCloud> target_ =
      std::make_shared<open3d::geometry::PointCloud>();
  Eigen::Matrix4d object_from_camera_ = Eigen::Matrix4d::Identity();
  int integrated_ = 0;
};

}  // namespace

std::unique_ptr<Open3dTracker> MakeFrameToModelTracker(const CameraIntrinsics& intrinsics,
                                                       const Open3dBaselineOptions& options) {
  return std::make_unique<FrameToModelTracker>(intrinsics, options);
}

}  // namespace ihs::bench
