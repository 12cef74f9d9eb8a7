#pragma once
// The KinectFusion-style scanner a user would otherwise pick, built from Open3D (Debian's
// libopen3d-dev): frame-to-frame RGB-D odometry (Steinbrücker et al. with Park et al.'s hybrid
// colour + depth term, Open3D's default) and Open3D's scalable TSDF integration, on frames whose
// hand pixels the caller has removed (the benchmark uses the ground truth's labels: every
// advantage). The object is taken as the static scene and the camera as what moves, which is the
// same thing seen from the object. Open3D's headers stay in the .cc file; without Open3D the
// benchmark leaves this method out (Open3dAvailable()).

#include <memory>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/trajectory_io.h"
#include "core/triangle_mesh.h"

namespace ihs::bench {

/// Whether this build has Open3D.
bool Open3dAvailable();

struct Open3dBaselineOptions {
  /// Voxel edge, mm (ours: a 350 mm cube at 256³ → 1.37 mm).
  double voxel_mm = 350.0 / 256.0;
  /// Truncation of the signed distance, voxels (ours: 4).
  double truncation_voxels = 4.0;
  /// Depth beyond this is ignored, mm (the paper's crop volume ends at 1 m).
  double max_depth_mm = 1000.0;
  /// Odometry: largest depth difference of a correspondence, mm (Open3D's default: 30).
  double max_depth_difference_mm = 30.0;
  /// Odometry: Gauss-Newton iterations per pyramid level, coarse to fine (Open3D's default).
  std::vector<int> iterations = {20, 10, 5};
};

/// What the baseline produced.
struct Open3dBaselineResult {
  /// Open3D's marching-cubes mesh, object frame (the first frame's camera frame), mm.
  TriangleMesh raw;
  /// cam_from_object of every registered frame, stamped with its depth timestamp.
  std::vector<StampedPose> trajectory;
  int frames = 0;
  /// Frames where the odometry reported failure (not integrated; the pose is carried on).
  int odometry_failures = 0;
  /// Frames with no depth left after removing the hand (skipped).
  int empty_frames = 0;
  double odometry_ms = 0, integrate_ms = 0;  ///< Mean per processed frame.
};

class Open3dBaseline {
 public:
  /// Throws std::runtime_error when this build has no Open3D.
  Open3dBaseline(const CameraIntrinsics& intrinsics, Open3dBaselineOptions options = {});
  ~Open3dBaseline();
  Open3dBaseline(const Open3dBaseline&) = delete;
  Open3dBaseline& operator=(const Open3dBaseline&) = delete;

  /// Registers and integrates one frame; `keep` (one byte per pixel, non-zero = object) says
  /// which pixels to use.
  void Process(const Frame& frame, const std::vector<std::uint8_t>& keep);
  /// Extracts the mesh and returns everything; call once, after the last frame.
  Open3dBaselineResult Finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace ihs::bench
