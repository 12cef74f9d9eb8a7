#pragma once
// Inside the Open3D baseline (built only with Open3D): the two trackers behind Open3dBaseline.
// Each takes the frame's depth with the hand removed and its colour, finds the camera's pose in
// the object frame (the first frame's camera frame) and integrates the frame into its TSDF.

#include <open3d/geometry/TriangleMesh.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "tools/bench/open3d_baseline.h"

namespace ihs::bench {

/// One frame's outcome.
struct Open3dStep {
  /// Whether the frame was tracked (and integrated); else it is left out of the trajectory.
  bool tracked = true;
  /// The camera in the object frame, metres.
  Eigen::Matrix4d object_from_camera = Eigen::Matrix4d::Identity();
  double odometry_ms = 0, integrate_ms = 0, raycast_ms = 0;
};

class Open3dTracker {
 public:
  virtual ~Open3dTracker() = default;
  /// `depth_mm`: one value per pixel, 0 where there is none (the hand's pixels too); `rgb`:
  /// three bytes per pixel (zeros when the frame has no colour). At least one depth value.
  virtual Open3dStep Track(const std::vector<std::uint16_t>& depth_mm,
                           const std::vector<std::uint8_t>& rgb) = 0;
  /// The TSDF's surface, metres.
  virtual open3d::geometry::TriangleMesh Mesh() = 0;
};

/// Frame-to-frame RGB-D odometry and the scalable TSDF (open3d_baseline.cc).
std::unique_ptr<Open3dTracker> MakeFrameToFrameTracker(const CameraIntrinsics& intrinsics,
                                                       const Open3dBaselineOptions& options);
/// Open3D's dense SLAM model: frame to model (open3d_frame_to_model.cc).
std::unique_ptr<Open3dTracker> MakeFrameToModelTracker(const CameraIntrinsics& intrinsics,
                                                       const Open3dBaselineOptions& options);

}  // namespace ihs::bench
