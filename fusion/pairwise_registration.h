#pragma once
// The paper's pairwise registration (§3.3): the object's motion between the previous and the
// current frame from three sets of corresponding object points — SIFT matches back-projected to
// 3D, ISS3D + CSHOT matches, and the fingertip contacts the hand tracker holds — as the rigid
// transform minimising E = E_feat2d + E_feat3d + γt·E_contact (sums of squared point distances).
// The visual sets are cleaned by RANSAC first; the contacts come from the tracker and are kept.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/rigid3.h"

namespace ihs::fusion {

/// One object point seen in both frames (camera frame, mm).
struct PointMatch {
  Eigen::Vector3d previous;
  Eigen::Vector3d current;
};

/// The correspondences of one frame pair.
struct PairwiseInput {
  std::vector<PointMatch> features_2d;  ///< SIFT matches, back-projected.
  std::vector<PointMatch> features_3d;  ///< ISS3D + CSHOT matches.
  std::vector<PointMatch> contacts;     ///< Contact vertices held in both frames.
};

/// Options of the pairwise registration (defaults: the paper's γt; RANSAC as usual).
struct PairwiseOptions {
  /// γt, weight of each contact pair against one visual pair (paper: 15; 0 ignores contacts).
  double contact_weight = 15.0;
  /// Weight of the visual pairs (0 ignores them: contacts only).
  double visual_weight = 1.0;
  /// RANSAC over the visual pairs: hypotheses, inlier distance (mm) and the fewest inliers a
  /// visual set needs to count.
  int ransac_iterations = 300;
  double inlier_mm = 5.0;
  int min_visual_inliers = 6;
  /// Contact pairs needed when they are all there is.
  int min_contacts = 3;
  /// Contacts count only when they spread at least this far (their largest standard deviation
  /// in the previous frame, mm): one fingertip's patch (the paper asks for two contact bones)
  /// pins a point of the object, not its turn.
  double min_contact_spread_mm = 20.0;
  /// With a consistent visual set, contacts farther than `inlier_mm` from where its motion puts
  /// them are dropped (a mistracked fingertip; γt times hundreds of contact vertices would
  /// outweigh every feature match).
  bool check_contacts = true;
  /// Seed of the RANSAC sampling (results are deterministic).
  std::uint32_t seed = 1;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The result: `current_from_previous` moves the object's points from the previous camera-frame
/// position to the current one.
struct PairwiseResult {
  bool ok = false;
  /// Why no motion was found (empty when ok).
  std::string reason;
  Rigid3 current_from_previous;
  /// Pairs used: visual inliers and contacts.
  int visual_inliers = 0;
  int contacts = 0;
  /// Contacts dropped because the visual inliers contradict them (PairwiseOptions::check_contacts).
  int contacts_rejected = 0;
  /// The contacts' spread (see PairwiseOptions::min_contact_spread_mm), mm.
  double contact_spread_mm = 0;
  /// Root mean square distance of the used pairs after the solve, mm.
  double rms_mm = 0;
};

/// Solves one frame pair.
PairwiseResult RegisterPair(const PairwiseInput& input, const PairwiseOptions& options = {});

}  // namespace ihs::fusion
