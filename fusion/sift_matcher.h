#pragma once
// Visual correspondences between consecutive frames (paper §3.3, E_feat2d): SIFT keypoints on the
// object's pixels of the colour image, matched to the previous frame's by Lowe's ratio test, each
// match back-projected to 3D with its depth. Hand pixels never count: only the object mask is
// searched.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "fusion/correspondence_source.h"

namespace ihs::fusion {

/// Options of the SIFT matcher.
struct SiftOptions {
  /// Keypoints kept per frame, strongest first.
  int max_features = 500;
  /// Lowe's ratio: a match counts when its distance is below this share of the second best's.
  double ratio = 0.8;
  /// A keypoint counts only when the disc of this many times its radius (OpenCV's
  /// KeyPoint::size / 2; its descriptor's window is about ten times that) lies on the object's
  /// pixels: one on the object's edge describes the hand or the background beside it too, and
  /// moves with the hand, or stands with the outline of a bottle spinning about its axis. 0: any
  /// keypoint on the object's pixels. Off: on 37 generated full turns it moved single turns by
  /// tens of degrees either way, no better on the whole (docs/fusion.md, 2026-11-30).
  double support_inside = 0.0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// SIFT keypoints of a frame's object pixels: where each is (camera frame, mm, from its depth)
/// and its descriptor.
struct ObjectKeypoints {
  std::vector<Eigen::Vector3f> points;
  /// 128 floats a keypoint, keypoint after keypoint.
  std::vector<float> descriptors;
  static constexpr int kDescriptorSize = 128;
  size_t size() const { return points.size(); }
};

/// The keypoints of `frame` inside `object_mask` (non-zero pixels, with depth), strongest first
/// (SiftMatcher's detector); none without colour.
ObjectKeypoints DetectObjectKeypoints(const Frame& frame,
                                      const std::vector<std::uint8_t>& object_mask,
                                      const CameraIntrinsics& intrinsics,
                                      const SiftOptions& options = {});

/// Matches each frame's object keypoints with the previous frame's. Not thread-safe.
class SiftMatcher final : public CorrespondenceSource {
 public:
  explicit SiftMatcher(const CameraIntrinsics& intrinsics, SiftOptions options = {});
  ~SiftMatcher() override;

  std::string name() const override { return "sift"; }
  MatchKind kind() const override { return MatchKind::kVisual; }
  /// Match(frame, object_mask) of the context's frame.
  std::vector<PointMatch> Match(const MatchContext& context) override;

  /// The keypoints of `frame` inside `object_mask` (non-zero pixels, with depth), matched with
  /// those of the previous call: (previous, current) 3D points, camera frame, mm, each with
  /// its keypoint's track as id (the same while the keypoint is matched from frame to frame,
  /// so the fusion can hold it at one point of the object: FusionOptions::anchor_features).
  /// The first call, and a frame without colour, give none.
  std::vector<PointMatch> Match(const Frame& frame, const std::vector<std::uint8_t>& object_mask);

 private:
  struct State;
  const CameraIntrinsics intrinsics_;
  const SiftOptions options_;
  std::unique_ptr<State> state_;
};

}  // namespace ihs::fusion
