#pragma once
// The scanner's two per-frame stages as the pipeline's threads run them, and the packet that
// carries a frame through them. HandStage: hand tracker, then the object's pixels without the
// posed hand model. ObjectStage: the correspondence sources' matches with the previous frame
// (SIFT, optionally ISS3D + CSHOT, the tracker's contact pairs), then registration, ICP and
// TSDF integration. Stage
// objects know nothing of threads; inhandscan-scan runs them one after the other, the Pipeline
// each on its own thread.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/scanner_options.h"
#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/triangle_mesh.h"
#include "fusion/object_fusion.h"
#include "tracker/hand_tracker.h"

namespace ihs::fusion {
class CorrespondenceSource;
}  // namespace ihs::fusion

namespace ihs::app {

/// One frame and what the stages found in it; it grows as it moves down the pipeline.
struct FramePacket {
  /// The frame, immutable after capture.
  std::shared_ptr<const Frame> frame;
  /// When the capture thread got it (for latency).
  std::chrono::steady_clock::time_point captured_at;
  /// Non-empty when the frame is malformed (inconsistent image sizes, or not the camera's
  /// size): no stage touches it.
  std::string frame_error;

  // Filled by HandStage.
  tracker::TrackResult track;
  /// The posed hand model (camera frame, mm) when the tracker has a pose.
  std::shared_ptr<const TriangleMesh> hand_mesh;
  /// Each fingertip's vertex indices in `hand_mesh` (the same for every frame of a scan).
  std::shared_ptr<const std::vector<std::vector<int>>> fingertips;
  /// Per pixel: non-zero where the object is, the hand model's pixels (dilated) removed.
  std::vector<std::uint8_t> object_mask;
  int hand_pixels_removed = 0;
  double mask_ms = 0;

  // Filled by ObjectStage.
  fusion::FusionResult fusion;
  /// Each correspondence source's pairs with the previous frame, by its name (in order).
  std::vector<std::pair<std::string, int>> matches;
  double features_ms = 0;
  /// From capture to fused, ms (set by whoever runs the stages).
  double latency_ms = 0;

  /// Whether the frame was registered (started or fused).
  bool Registered() const { return fusion.status != fusion::FusionStatus::kSkipped; }
  /// The hand's state for a person: "tracked", "doubtful" (a pose the data may not support),
  /// "lost" (no usable pose: no hand, a fit that diverged, an empty or malformed frame).
  const char* HandState() const;
  /// The object's state for a person: "registered" (the frame was fused), "turned by the hand"
  /// (fused, its free turn carried by the hand's: fusion/turn_carry.h), "paused" (not fused:
  /// no hand pose to go by), "lost" (not fused: the registration failed).
  const char* ObjectState() const;
};

/// The hand template `options` names, at its given scale (procedural or a scanned model).
/// Throws ihs::InputError when a scanned model cannot be read.
tracker::HandModel LoadHandTemplate(const ScanOptions& options);

/// The tracker's options with the template's scale estimate off (scale_frames = 0) when the
/// scale is given or the template is a scan of the user's own hand.
tracker::TrackerOptions TrackerOptionsFor(const ScannerOptions& options);

/// Hand tracking and the hand-free object mask.
class HandStage {
 public:
  /// Throws std::invalid_argument for bad options, ihs::InputError for an unreadable template.
  HandStage(const ScannerOptions& options, const CameraIntrinsics& intrinsics);
  ~HandStage();

  /// Starts the tracker from a known pose (benchmark mode) instead of the hand cloud.
  void Initialise(const tracker::HandPose& pose);
  /// Fills the packet's hand fields.
  void Process(FramePacket& packet);

  /// The template at its current scale.
  const tracker::HandModel& model() const { return tracker_.model(); }
  /// The template's scale relative to the one loaded (estimated or given).
  double scale() const;
  /// Whether an estimated scale lies on a bound of its range (tracker::HandTracker).
  bool scale_at_bound() const { return tracker_.scale_at_bound(); }
  /// Names of the template's bones (the joints' columns).
  std::vector<std::string> BoneNames() const;
  /// The joint angles' names in HandPose::angles_rad order: "BONE.x", "BONE.y" or "BONE.z", the
  /// rotation about that axis of the bone (tracker::JointDegreesOfFreedom).
  std::vector<std::string> AngleNames() const;

 private:
  const ScanOptions options_;
  const CameraIntrinsics intrinsics_;
  tracker::HandTracker tracker_;
  std::shared_ptr<const std::vector<std::vector<int>>> fingertips_;
};

/// The correspondence sources the options turn on, in the registration's order: SIFT
/// (scan.features_2d), ISS3D + CSHOT (scan.features_3d), the hand's contacts (always; γt = 0,
/// fusion.pairwise.contact_weight, leaves them out of the registration). The one place that
/// names them: a new source is one line here and one option.
std::vector<std::unique_ptr<fusion::CorrespondenceSource>> MakeCorrespondenceSources(
    const ScannerOptions& options, const CameraIntrinsics& intrinsics);

/// Correspondences, registration, ICP and the TSDF: the model belongs to this stage.
class ObjectStage {
 public:
  ObjectStage(const ScannerOptions& options, const CameraIntrinsics& intrinsics);
  ~ObjectStage();

  /// Fills the packet's fusion fields (a malformed frame is skipped with its reason).
  void Process(FramePacket& packet);
  /// The model so far as an export needs it (an immutable copy).
  fusion::ModelSnapshot Snapshot() const;
  /// Whether the model has been started (a first frame fused).
  bool started() const { return fusion_.started(); }
  /// The model (for a raycast view); only the owning thread may read it.
  const fusion::TsdfVolume& volume() const { return fusion_.volume(); }

 private:
  // The hand's motion since the previous frame, where the tracker followed it from there.
  std::optional<Rigid3> HandMotion(const FramePacket& packet);
  // How loose this frame's contact pairs are: each joins a contact of this frame to one of the
  // previous frame, and is as loose as the looser of the two (FusionOptions::loose_contact_mm).
  void SetContactLooseness(const FramePacket& packet, fusion::FusionInput* input);

  const ScanOptions options_;
  std::vector<std::unique_ptr<fusion::CorrespondenceSource>> sources_;
  fusion::ObjectFusion fusion_;
  // The hand's root pose in the previous frame, where it had one.
  std::optional<Rigid3> previous_root_;
  // The previous frame's contacts: the threshold they were found at, whether they were held.
  double previous_contact_threshold_mm_ = 0;
  bool previous_contacts_held_ = false;
};

}  // namespace ihs::app
