#pragma once
// 3D feature matches between consecutive frames, as the paper's E_feat3d: ISS3D keypoints (Zhong
// 2009) on the voxel-downsampled object cloud, described by CSHOT (SHOT with colour, Tombari et
// al. 2011), matched to the previous frame's by descriptor distance with a ratio test. PCL stays
// in the .cc file.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "fusion/correspondence_source.h"

namespace ihs::fusion {

/// Options of the ISS3D + CSHOT matcher (radii as multiples of the cloud's resolution, after
/// the authors' configuration).
struct ShotOptions {
  /// Voxel size of the downsampled object cloud: the cloud's resolution, mm.
  double resolution_mm = 2.0;
  /// Normals from neighbours within this many resolutions.
  double normal_radius = 3.0;
  /// ISS salient radius and non-maximum suppression radius (authors: 6 and 3).
  double salient_radius = 6.0;
  double non_max_radius = 3.0;
  /// CSHOT support radius (the authors use 30 resolutions of a finer cloud; 15 of ours, 30 mm).
  double support_radius = 15.0;
  /// A match counts when its descriptor distance is below this share of the second best's.
  double ratio = 0.8;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Matches each frame's object keypoints with the previous frame's. Not thread-safe.
class ShotMatcher final : public CorrespondenceSource {
 public:
  explicit ShotMatcher(const CameraIntrinsics& intrinsics, ShotOptions options = {});
  ~ShotMatcher() override;

  std::string name() const override { return "shot"; }
  MatchKind kind() const override { return MatchKind::kVisual; }
  /// Match(frame, object_mask) of the context's frame.
  std::vector<PointMatch> Match(const MatchContext& context) override;

  /// The ISS3D keypoints of the object's points (`object_mask` non-zero, with depth), matched by
  /// CSHOT with those of the previous call: (previous, current) 3D points, camera frame, mm.
  /// The first call gives none.
  std::vector<PointMatch> Match(const Frame& frame, const std::vector<std::uint8_t>& object_mask);

 private:
  struct State;
  const CameraIntrinsics intrinsics_;
  const ShotOptions options_;
  std::unique_ptr<State> state_;
};

}  // namespace ihs::fusion
