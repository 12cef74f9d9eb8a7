#pragma once
// What a scan keeps besides the model: per-frame statistics (status, reason, stage timings), the
// object's trajectory, the hand's joints and poses; and the files they go to. Owned by whoever
// runs the last stage (the fusion thread); copies are snapshots for an export in mid-scan.

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "app/scan_stages.h"
#include "core/trajectory_io.h"
#include "tracker/hand_joints_io.h"

namespace ihs::app {

/// How trajectory.txt states the object's motion (TUM lines "time tx ty tz qx qy qz qw").
enum class TrajectoryFormat {
  kCamFromObjectMm,  ///< "mm": cam_from_object, millimetres (the default).
  kTumMetres,  ///< "tum-m": the camera's pose in the object's frame (object_from_cam), metres,
               ///< as the TUM benchmark's and evo's tools read a camera trajectory.
};

/// "mm" or "tum-m"; throws std::invalid_argument otherwise.
TrajectoryFormat ParseTrajectoryFormat(const std::string& name);

/// Per-frame log of a scan.
class ScanRecord {
 public:
  /// `bone_names` name the joints' columns in hand_joints.csv, `angle_names` the joint angles'
  /// columns in hand_poses.csv (HandStage::AngleNames; without them the header says "angles...").
  explicit ScanRecord(std::vector<std::string> bone_names = {},
                      std::vector<std::string> angle_names = {});

  /// Records a frame both stages have processed.
  void Add(const FramePacket& packet);
  /// Frames recorded (processed, not dropped).
  std::int64_t frames() const { return frames_; }
  /// Frames registered into the model.
  std::int64_t registered() const { return static_cast<std::int64_t>(trajectory_.size()); }
  /// Frames skipped by the fusion stage, by the reason's kind.
  const std::map<std::string, std::int64_t>& skip_reasons() const { return skip_reasons_; }
  /// The share of directions around the object seen so far (fusion::FusionResult::coverage).
  double coverage() const { return coverage_; }
  /// The object's pose in each registered frame (cam_from_object, mm).
  const std::vector<StampedPose>& trajectory() const { return trajectory_; }

  /// What to tell a user whose scan registered no frame: "nothing was scanned: no frame could
  /// be registered (no hand × 12; …)", the skip reasons counted.
  std::string NothingScanned() const;
  /// Totals: counts by status and reason, mean ms per stage, latency percentiles.
  nlohmann::json Summary() const;

  /// Writes trajectory.txt, hand_joints.csv and hand_poses.csv into `folder`.
  void WriteTables(const std::filesystem::path& folder,
                   TrajectoryFormat trajectory = TrajectoryFormat::kCamFromObjectMm) const;
  /// Writes `path` as {"summary": Summary() merged with `extra`, "frames": [...]}.
  void WriteStats(const std::filesystem::path& path, const nlohmann::json& extra) const;

 private:
  std::vector<std::string> bone_names_;
  std::vector<std::string> angle_names_;
  std::int64_t frames_ = 0;
  std::int64_t doubtful_frames_ = 0;  // Frames whose hand pose was doubtful.
  // Frames where the fit turned over (palm for back) replaced the tracked one.
  std::int64_t turned_over_frames_ = 0;
  // Frames whose thumb the thumb check moved (tracker::TrackerOptions::thumb_check).
  std::int64_t thumb_moved_frames_ = 0;
  // Frames whose grasp the release watch saw let go (tracker::ReleaseWatch).
  std::int64_t let_go_frames_ = 0;
  // Frames whose contacts were a grasp held without being detected (tracker::GraspHold).
  std::int64_t held_grasp_frames_ = 0;
  // Frames whose ICP slid off what it started on (IcpOptions::min_kept_pair_fraction).
  std::int64_t icp_slid_frames_ = 0;
  // Keyframes kept, loops closed and drift corrections made (keyframe_graph.h).
  std::int64_t keyframes_ = 0;
  std::int64_t loops_ = 0;
  std::int64_t feature_loops_ = 0;
  // The last FusionResult::keypoint_alias_deg (0: none).
  double keypoint_alias_deg_ = 0;
  std::int64_t loop_corrections_ = 0;
  // Frames the colour alignment moved (colour_align.h).
  std::int64_t colour_frames_ = 0;
  std::int64_t colour_still_frames_ = 0;
  // Frames that showed the object mostly hidden: tracked, not integrated (fusion/hidden_span.h).
  std::int64_t hidden_frames_ = 0;
  // Frames that saw through the model at their pose: held out, and moved onto the object's
  // points (fusion/see_through.h).
  std::int64_t see_through_held_frames_ = 0;
  std::int64_t see_through_moved_frames_ = 0;
  // Implausible jumps taken because they held (FusionOptions::jump_held_frames).
  std::int64_t jumps_taken_ = 0;
  // Frames the hand carried the object's turn, and frames it turned back (turn_carry.h).
  std::int64_t hand_carried_frames_ = 0;
  std::int64_t hand_back_frames_ = 0;
  std::int64_t hand_undecided_frames_ = 0;
  double hand_caught_up_deg_ = 0;
  std::vector<std::string> frame_json_;  // One serialised object per recorded frame.
  std::map<std::string, std::int64_t> track_counts_, fusion_counts_, skip_reasons_;
  std::map<std::string, std::pair<double, std::int64_t>> stage_ms_;  // Sum and count.
  std::vector<double> latencies_ms_;
  double coverage_ = 0;
  std::vector<StampedPose> trajectory_;
  std::vector<tracker::HandJointsRow> joints_;
  std::vector<std::string> pose_rows_;  // hand_poses.csv lines.
};

}  // namespace ihs::app
