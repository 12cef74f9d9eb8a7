#pragma once
// The KinectFusion-style scanners a user would otherwise pick, built from Open3D (Debian's
// libopen3d-dev), on frames whose hand pixels the caller has removed (the benchmark uses the
// ground truth's labels: every advantage). Two trackers:
// - frame to frame: RGB-D odometry between consecutive frames (Steinbrücker et al. with Park et
//   al.'s hybrid colour + depth term, Open3D's default) and Open3D's scalable TSDF;
// - frame to model (KinectFusion's loop, as Open3D's dense SLAM runs it): Open3D's voxel-block
//   TSDF raycast at the last pose, the new frame aligned to that view by Open3D's point-to-plane
//   ICP, then integrated.
// The object is taken as the static scene and the camera as what moves, which is the same thing
// seen from the object. Open3D's headers stay in the .cc files; without Open3D the benchmark
// leaves these methods out (Open3dAvailable()).

#include <memory>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/trajectory_io.h"
#include "core/triangle_mesh.h"

namespace ihs::bench {

/// Whether this build has Open3D.
bool Open3dAvailable();

/// Which of Open3D's trackers.
enum class Open3dTracking { kFrameToFrame, kFrameToModel };

/// The benchmark's name of the tracker's method: "open3d" (frame to frame), "open3d-f2m".
inline std::string Open3dMethodName(Open3dTracking tracking) {
  return tracking == Open3dTracking::kFrameToModel ? "open3d-f2m" : "open3d";
}

struct Open3dBaselineOptions {
  Open3dTracking tracking = Open3dTracking::kFrameToFrame;
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

  // Frame to model.
  /// Truncation of its signed distance, voxels (Open3D's dense SLAM's default: 8).
  double model_truncation_voxels = 8.0;
  /// ICP: largest distance of a correspondence, mm (a few frames' motion of a turned object).
  double model_max_distance_mm = 20.0;
  /// ICP: at most this many iterations (Open3D's default: 30).
  int model_iterations = 30;
  /// ICP: the frame's and the model's points are thinned to one per cell of this edge, mm.
  double model_sample_mm = 2.0;
  /// A frame is not tracked (kept at the last pose, not integrated) when fewer of its points
  /// than this share have a correspondence in the model, or when it moved farther than
  /// `max_step_mm` since the last frame (the checks of Open3D's dense SLAM: 0.1 and 150 mm).
  double min_fitness = 0.1;
  double max_step_mm = 150.0;
  /// Voxels per block edge and the blocks reserved at first (the map grows as needed).
  int block_resolution = 16;
  int block_count = 1000;
  /// Voxels integrated fewer times than this are left out of the mesh (Open3D's default: 3;
  /// its raycast leaves out those integrated fewer times than min(frames so far, 3)).
  double weight_threshold = 3.0;
};

/// What the baseline produced.
struct Open3dBaselineResult {
  /// Open3D's marching-cubes mesh, object frame (the first frame's camera frame), mm.
  TriangleMesh raw;
  /// cam_from_object of every registered frame, stamped with its depth timestamp.
  std::vector<StampedPose> trajectory;
  int frames = 0;
  /// Frames where the odometry reported failure, or (frame to model) failed Open3D's checks:
  /// not integrated, not in the trajectory.
  int odometry_failures = 0;
  /// Frames with no depth left after removing the hand (skipped).
  int empty_frames = 0;
  /// Mean per processed frame: odometry (or ICP against the model), TSDF integration, raycast of
  /// the model (frame to model only).
  double odometry_ms = 0, integrate_ms = 0, raycast_ms = 0;
};

class Open3dBaseline {
 public:
  /// Throws std::runtime_error when this build has no Open3D, std::invalid_argument for bad
  /// options.
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
