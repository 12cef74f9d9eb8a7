#include "app/scan_record.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"

namespace ihs::app {
namespace {

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  const std::size_t k =
      std::min(values.size() - 1, static_cast<std::size_t>(fraction * values.size()));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

}  // namespace

ScanRecord::ScanRecord(std::vector<std::string> bone_names, std::vector<std::string> angle_names)
    : bone_names_(std::move(bone_names)), angle_names_(std::move(angle_names)) {}

void ScanRecord::Add(const FramePacket& packet) {
  const Frame& frame = *packet.frame;
  nlohmann::json entry = {{"frame", frame.index}, {"timestamp_us", frame.depth_timestamp_us}};
  auto timing = [&](const char* key, double ms) {
    entry[key] = ms;
    auto& [sum, count] = stage_ms_[key];
    sum += ms;
    ++count;
  };
  if (!packet.frame_error.empty()) {
    entry["track"] = "malformed";
    ++track_counts_["malformed"];
  } else {
    const tracker::TrackResult& track = packet.track;
    entry["track"] = tracker::ToString(track.status);
    ++track_counts_[tracker::ToString(track.status)];
    if (!track.reason.empty()) entry["track_reason"] = track.reason;
    if (track.doubtful) entry["track_doubtful"] = true, ++doubtful_frames_;
    if (track.turned_over) entry["track_turned_over"] = true, ++turned_over_frames_;
    if (track.thumb_moved) entry["track_thumb_moved"] = true, ++thumb_moved_frames_;
    if (track.grasp_let_go) entry["grasp_let_go"] = true, ++let_go_frames_;
    timing("track_ms", track.milliseconds);
    timing("segmentation_ms", track.segmentation_ms);
    timing("hand_fit_ms", track.fit_ms);
    timing("contacts_ms", track.contacts_ms);
    timing("mask_ms", packet.mask_ms);
    timing("features_ms", packet.features_ms);
    entry["hand_pixels_removed"] = packet.hand_pixels_removed;
    if (!track.contacts.bones.empty()) {
      entry["contact_bones"] = track.contacts.bones.size();
      entry["contact_threshold_mm"] = track.contacts.threshold_mm;
      if (track.contacts.held_frames > 0) {
        entry["contact_held_frames"] = track.contacts.held_frames;
        ++held_grasp_frames_;
      }
    }
    nlohmann::json& matches = entry["matches"] = nlohmann::json::object();
    for (const auto& [source, count] : packet.matches) matches[source] = count;
    if (!track.joints_mm.empty()) joints_.push_back({frame.index, track.joints_mm});
    if (track.HasPose()) {
      const Eigen::Quaterniond q = track.pose.cam_from_root.quaternion();
      const Eigen::Vector3d t = track.pose.cam_from_root.translation();
      std::vector<double> values = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
      values.insert(values.end(), track.pose.angles_rad.begin(), track.pose.angles_rad.end());
      std::string row = std::to_string(frame.index);
      char buffer[48];
      for (double value : values) {
        std::snprintf(buffer, sizeof(buffer), ",%.6g", value);
        row += buffer;
      }
      pose_rows_.push_back(std::move(row));
    }
  }
  const fusion::FusionResult& fused = packet.fusion;
  entry["fusion"] = fusion::ToString(fused.status);
  ++fusion_counts_[fusion::ToString(fused.status)];
  if (packet.frame_error.empty()) {
    timing("fusion_ms", fused.milliseconds);
    timing("pairwise_ms", fused.pairwise_ms);
    timing("raycast_ms", fused.raycast_ms);
    timing("icp_ms", fused.icp_ms);
    timing("colour_ms", fused.colour_ms);
    timing("integrate_ms", fused.integrate_ms);
    entry["coverage"] = fused.coverage;
    coverage_ = fused.coverage;
    entry["anchored_contacts"] = fused.anchored_contacts;
    entry["anchored_features"] = fused.anchored_features;
    entry["features_moving_back"] = fused.features_moving_back;
    entry["model_contacts"] = fused.model_contacts;
    entry["icp_anchors"] = fused.icp_anchors;
    entry["contact_residual_mm"] = fused.contact_residual_mm;
    entry["contact_noise_mm"] = fused.contact_noise_mm;
    entry["contact_spread_mm"] = fused.pairwise.contact_spread_mm;
    entry["contacts_rejected"] = fused.pairwise.contacts_rejected;
    entry["visual_turn_deg"] = fused.pairwise.visual_turn_deg;
    entry["visual_turn_kept"] = fused.pairwise.visual_turn_kept;
    if (fused.hand_turn != fusion::HandTurn::kUnknown) {
      entry["hand_turn"] = fusion::ToString(fused.hand_turn);
      if (fused.hand_turn == fusion::HandTurn::kBack) ++hand_back_frames_;
      if (fused.hand_turn == fusion::HandTurn::kUndecided) ++hand_undecided_frames_;
    }
    if (fused.hand_caught_up_deg > 0) {
      entry["hand_caught_up_deg"] = fused.hand_caught_up_deg;
      hand_caught_up_deg_ += fused.hand_caught_up_deg;
    }
    if (fused.colour.shading_share > 0) {
      entry["colour_shading_share"] = fused.colour.shading_share;
      entry["colour_pattern_spread"] = fused.colour.pattern_spread;
    }
    if (fused.colour.applied) {
      entry["colour_moved_mm"] = fused.colour.moved_mm;
      entry["colour_turn_deg"] = fused.colour.turn_deg;
      entry["colour_uncertainty_mm"] = fused.colour.uncertainty_mm;
      entry["colour_correlation"] = fused.colour.correlation;
      ++colour_frames_;
    } else if (!fused.colour.reason.empty()) {
      entry["colour_skipped"] = fused.colour.reason;
    }
    // The still pose may win where its colours had nothing to better (not applied).
    if (std::isfinite(fused.colour_still_correlation)) {
      entry["colour_still_correlation"] = fused.colour_still_correlation;
    }
    if (fused.colour_kept_still) {
      entry["colour_kept_still"] = true;
      ++colour_still_frames_;
    }
    if (fused.hand_blended_deg != 0) entry["hand_blended_deg"] = fused.hand_blended_deg;
    if (fused.hand_carried_deg > 0) {
      entry["hand_carried_deg"] = fused.hand_carried_deg;
      ++hand_carried_frames_;
    }
    if (fused.pairwise.ok) {
      // The correspondences' motion before ICP: tx ty tz qx qy qz qw (mm), for diagnosis.
      const Eigen::Quaterniond q = fused.pairwise.current_from_previous.quaternion();
      const Eigen::Vector3d t = fused.pairwise.current_from_previous.translation();
      entry["pairwise_motion"] = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
    }
    if (fused.pairwise.rms_mm > 0) {
      // Also where the motion was refused for it (PairwiseOptions::max_rms_mm).
      entry["pairwise_rms_mm"] = fused.pairwise.rms_mm;
      entry["visual_inliers"] = fused.pairwise.visual_inliers;
    }
    if (fused.icp_from_previous) entry["icp_from_previous"] = true;
    if (fused.hidden && fused.status != fusion::FusionStatus::kSkipped) {
      entry["hidden"] = true;
      ++hidden_frames_;
    }
    if (std::isfinite(fused.see_through_share)) {
      entry["see_through_share"] = fused.see_through_share;
    }
    if (fused.see_through_moved) entry["see_through_moved"] = true, ++see_through_moved_frames_;
    if (fused.see_through_held && fused.status != fusion::FusionStatus::kSkipped) {
      entry["see_through_held"] = true;
      ++see_through_held_frames_;
    }
    if (fused.jump_taken) entry["jump_taken"] = true, ++jumps_taken_;
    if (fused.keyframe) entry["keyframe"] = true, ++keyframes_;
    if (fused.loops > 0) entry["loops"] = fused.loops, loops_ += fused.loops;
    if (fused.feature_loops > 0) {
      entry["feature_loops"] = fused.feature_loops;
      feature_loops_ += fused.feature_loops;
    }
    if (fused.keypoint_alias_deg > 0) keypoint_alias_deg_ = fused.keypoint_alias_deg;
    if (fused.loop_correction_mm > 0) {
      entry["loop_correction_mm"] = fused.loop_correction_mm;
      entry["refuse_ms"] = fused.refuse_ms;
      ++loop_corrections_;
    }
    if (fused.icp.iterations > 0) {
      entry["icp_inliers"] = fused.icp.inliers;
      entry["icp_first_inliers"] = fused.icp.first_inliers;
      entry["icp_points"] = fused.icp.points;
      if (fused.icp.slid) entry["icp_slid"] = true, ++icp_slid_frames_;
      if (fused.icp.free_directions >= 0) entry["icp_free_directions"] = fused.icp.free_directions;
      if (fused.icp.contour_pairs > 0) entry["icp_contour_pairs"] = fused.icp.contour_pairs;
      entry["icp_rms_mm"] = fused.icp.rms_mm;
    }
  }
  if (packet.latency_ms > 0) {
    entry["latency_ms"] = packet.latency_ms;
    latencies_ms_.push_back(packet.latency_ms);
  }
  if (fused.status == fusion::FusionStatus::kSkipped) {
    entry["fusion_reason"] = fused.reason;
    ++skip_reasons_[fused.reason.substr(0, fused.reason.find(':'))];
  } else {
    trajectory_.push_back({frame.depth_timestamp_us * 1e-6, fused.cam_from_object});
  }
  frame_json_.push_back(entry.dump());
  ++frames_;
}

std::string ScanRecord::NothingScanned() const {
  std::string skipped;
  for (const auto& [reason, count] : skip_reasons_)
    skipped += (skipped.empty() ? "" : ", ") + reason + " × " + std::to_string(count);
  return "nothing was scanned: no frame could be registered (" +
         (skipped.empty() ? std::string("none was skipped") : skipped) +
         "; stats.json has each frame's reason)";
}

nlohmann::json ScanRecord::Summary() const {
  nlohmann::json ms = nlohmann::json::object();
  for (const auto& [key, sum_count] : stage_ms_) {
    const std::string name = key.substr(0, key.size() - 3);  // "track_ms" → "track".
    ms[name] = sum_count.second ? sum_count.first / sum_count.second : 0.0;
  }
  nlohmann::json summary = {{"frames", frames_},
                            {"registered_frames", registered()},
                            {"track_status_counts", track_counts_},
                            {"hand_doubtful_frames", doubtful_frames_},
                            {"hand_turned_over_frames", turned_over_frames_},
                            {"hand_thumb_moved_frames", thumb_moved_frames_},
                            {"held_grasp_frames", held_grasp_frames_},
                            {"grasps_let_go", let_go_frames_},
                            {"icp_slid_frames", icp_slid_frames_},
                            {"keyframes", keyframes_},
                            {"loops", loops_},
                            {"feature_loops", feature_loops_},
                            {"keypoint_alias_deg", keypoint_alias_deg_},
                            {"loop_corrections", loop_corrections_},
                            {"colour_aligned_frames", colour_frames_},
                            {"colour_still_frames", colour_still_frames_},
                            {"hidden_frames", hidden_frames_},
                            {"see_through_held_frames", see_through_held_frames_},
                            {"see_through_moved_frames", see_through_moved_frames_},
                            {"jumps_taken", jumps_taken_},
                            {"hand_carried_frames", hand_carried_frames_},
                            {"hand_back_frames", hand_back_frames_},
                            {"hand_undecided_frames", hand_undecided_frames_},
                            {"hand_caught_up_deg", hand_caught_up_deg_},
                            {"fusion_status_counts", fusion_counts_},
                            {"skip_reasons", skip_reasons_},
                            {"coverage", coverage_},
                            {"ms_per_frame", ms}};
  if (!latencies_ms_.empty()) {
    summary["latency_ms"] = {
        {"p50", Percentile(latencies_ms_, 0.5)},
        {"p95", Percentile(latencies_ms_, 0.95)},
        {"max", *std::max_element(latencies_ms_.begin(), latencies_ms_.end())}};
  }
  return summary;
}

TrajectoryFormat ParseTrajectoryFormat(const std::string& name) {
  if (name == "mm") return TrajectoryFormat::kCamFromObjectMm;
  if (name == "tum-m") return TrajectoryFormat::kTumMetres;
  throw std::invalid_argument("trajectory format '" + name + "': mm or tum-m");
}

void ScanRecord::WriteTables(const std::filesystem::path& folder,
                             TrajectoryFormat trajectory) const {
  if (trajectory == TrajectoryFormat::kCamFromObjectMm) {
    WriteTumTrajectory(folder / "trajectory.txt", trajectory_,
                       {"cam_from_object of the scanned object (mm), registered frames only"});
  } else {
    std::vector<StampedPose> camera;
    for (const StampedPose& pose : trajectory_) {
      const Rigid3 object_from_cam = pose.transform.Inverse();
      camera.push_back(
          {pose.time_s, Rigid3(object_from_cam.rotation(), object_from_cam.translation() / 1000)});
    }
    WriteTumTrajectory(folder / "trajectory.txt", camera,
                       {"the camera's pose in the scanned object's frame (object_from_cam, "
                        "metres), registered frames only"});
  }
  tracker::WriteHandJointsCsv(folder / "hand_joints.csv", bone_names_, joints_);
  std::string poses =
      "# hand pose per tracked frame: cam_from_root (mm; quaternion x y z w), then the joint "
      "angles (rad) in the template's degree-of-freedom order, BONE.x/.y/.z the rotation about "
      "the bone's x (about twist), y (flexion) or z (spread) axis\nframe,tx,ty,tz,qx,qy,qz,qw";
  if (angle_names_.empty()) poses += ",angles...";
  for (const std::string& name : angle_names_) poses += "," + name;
  poses += "\n";
  for (const std::string& row : pose_rows_) poses += row + "\n";
  WriteFileAtomically(folder / "hand_poses.csv", poses);
}

void ScanRecord::WriteStats(const std::filesystem::path& path, const nlohmann::json& extra) const {
  nlohmann::json summary = Summary();
  summary.update(extra);
  std::string text = "{\"summary\": " + summary.dump(1) + ",\n\"frames\": [\n";
  for (std::size_t i = 0; i < frame_json_.size(); ++i) {
    text += frame_json_[i];
    text += i + 1 < frame_json_.size() ? ",\n" : "\n";
  }
  text += "]}\n";
  WriteFileAtomically(path, text);
}

}  // namespace ihs::app
