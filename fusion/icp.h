#pragma once
// Refinement of the object's pose against the model, as KinectFusion does it: point-to-plane ICP
// between the current frame's object points and a raycast of the TSDF at the predicted pose,
// with projective data association (a point is paired with the model surface seen through its
// pixel). The cost per frame does not grow with the scan.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/rigid3.h"
#include "fusion/silhouette.h"
#include "fusion/tsdf_volume.h"

namespace ihs::fusion {

/// A direction of an object's motion: the turn (radians per unit, about a centre given with
/// it) and the shift (mm per unit) it makes.
struct FreeDirection {
  Eigen::Vector3d turn = Eigen::Vector3d::Zero();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
};

/// Options of the ICP refinement (defaults: the paper's 5 mm correspondences).
struct IcpOptions {
  /// Gauss–Newton iterations at most; it stops earlier once a step moves less than 0.01 mm.
  int iterations = 15;
  /// Pairs farther apart than this are not used, mm (paper: 5).
  double max_distance_mm = 5.0;
  /// Fewer pairs than this share of the points (or than 50) and the result is not trusted.
  double min_inlier_fraction = 0.2;
  /// The anchors (contacts) together weigh this share of the surface's point pairs (each in
  /// proportion to its own weight): enough to hold what the surface leaves free (a sphere's
  /// turn, a cylinder's turn about its axis), too little to pull against what it fixes even
  /// weakly (a bottle's shoulder fixes its shift along the axis, which tracked fingertips get
  /// wrong by a millimetre or two from frame to frame). ObjectFusion scales it by how well the
  /// contacts agree with the registered motion (FusionOptions::contact_noise_reference_mm):
  /// this is the share at 1 mm of disagreement; the procedural hand's 2.5-2.8 mm gives 0.003.
  double anchor_share = 0.02;
  /// Without anchors, a direction of the motion that the surface constrains (per point pair)
  /// less than this many times its model's normal noise does (half the median squared
  /// difference of neighbouring normals) keeps the prediction: a sphere's three turns, a
  /// bottle's turn about its axis. There the model's small flaws, not the object's motion, would
  /// decide, and they spun a sphere by about 4° per frame that the truth turned by 0.1°. Turns
  /// are taken about where the model's normal lines meet (a sphere's centre, a point on a
  /// bottle's axis), so keeping them does not turn the object when its position is corrected.
  /// Measured ratios of free directions: 0.1-1.4 (10th-90th percentile; the sphere, bottle and
  /// pin sessions), 0.5-1.9 (rendered spheres in tests); of real ones: 6 and more (a bottle's
  /// shift along its axis), 2.6 and more (90 % of a textured box's frames), but 1.4-2.5 for the
  /// turn a noiseless 45 x 30 x 18 mm ellipsoid's cap fixes only weakly: 1.5 is a compromise,
  /// and a weakly fixed turn then keeps the prediction. 0 solves every direction.
  double min_constraint_over_noise = 1.5;
  /// Whether the anchors decide only the directions the surface leaves free (those the rule
  /// above keeps at the prediction without anchors), the surface alone all the others: for
  /// anchors that fix a point of the object but hardly its turn (one fingertip's patch), whose
  /// pull on what the surface fixes would be noise. Where the anchors know nothing of a free
  /// direction either, it keeps the prediction. ObjectFusion sets it per frame.
  bool anchors_free_directions_only = false;
  /// An ICP whose last iteration pairs fewer than this share of the points it paired at the
  /// prediction slid off what it started on (a face slipping along itself as the slivers that
  /// held it lose their pairs): its iterate that paired the most points is kept instead. On
  /// box and cube turns the final count stays at 0.72-1.0 of the first where ICP is right,
  /// 0.35 where it slid 15-20 mm off in one frame. 0 turns the guard off.
  double min_kept_pair_fraction = 0.5;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The refined pose and how well it fits.
struct IcpResult {
  bool ok = false;
  /// Why the result is not trusted (empty when ok).
  std::string reason;
  /// The object's pose in the current camera: `predicted` corrected.
  Rigid3 cam_from_volume;
  int inliers = 0;
  /// The frame's points, and how many paired with the model at the prediction (before the
  /// first step): a final count far below that says ICP slid off what it started on.
  int points = 0;
  int first_inliers = 0;
  /// Whether the guard against sliding (IcpOptions::min_kept_pair_fraction) kept an earlier
  /// iterate.
  bool slid = false;
  /// Root mean square point-to-plane distance of the final pairs, mm.
  double rms_mm = 0;
  int iterations = 0;
  /// How many directions of the motion the surface left free and kept at the prediction
  /// (IcpOptions::min_constraint_over_noise) in the last iteration: a ball's 3, a bottle's 1;
  /// -1 where that was not judged (anchors joined every direction, or the rule is off).
  int free_directions = -1;
  /// Where the turns were taken about (camera frame, mm): where the model's normal lines meet
  /// (a ball's centre, a point on a bottle's axis) where the free directions were judged, else
  /// the points' centroid.
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  /// The free directions of the last iteration as motions of the predicted camera's points
  /// (where the model's raycast is): a point q moves by turn × (q − free_centre) + shift per unit
  /// (turn in radians, shift in mm; unit vectors of ICP's scaled twist). Empty where none.
  std::vector<FreeDirection> free;
  Eigen::Vector3d free_centre = Eigen::Vector3d::Zero();
  /// Contour points paired with the model's edge in the last iteration (IcpContour).
  int contour_pairs = 0;
};

/// The frame's occluding contour for ICP's silhouette term (silhouette.h): each point that
/// finds the model's edge within `options.search_px` along its outline's normal adds a row of
/// `options.weight` (in surface pairs). The model raycast then reaches beyond the object's
/// pixels (MarkContourBand); `pairable` (the frame's object mask) keeps the surface pairs where
/// they were.
struct IcpContour {
  std::vector<ContourPoint> points;
  const std::vector<std::uint8_t>* pairable = nullptr;
  SilhouetteOptions options;
};

/// A point of the current frame (camera frame, mm) that must land at `target`, where the
/// prediction puts it (e.g. a fingertip contact moved by the pairwise registration), with a
/// relative weight among the anchors (IcpOptions::anchor_share sets their total). Anchors hold
/// what the surface alone cannot: a sphere's turn.
struct IcpAnchor {
  Eigen::Vector3d current;
  Eigen::Vector3d target;
  double weight = 1.0;
};

/// Aligns `points` (the current frame's object points, camera frame, mm) to `model` (the TSDF
/// raycast at `predicted`, the predicted cam_from_volume) seen by a camera with `intrinsics`,
/// together with `anchors` and, where given, the frame's `contour`. With `start`, the
/// iterations start from that cam_from_volume instead of `predicted` (the model still cast at
/// `predicted`): a pose a little off the one the model was cast at needs no new raycast.
IcpResult AlignToModel(const std::vector<Eigen::Vector3f>& points, const RaycastImage& model,
                       const CameraIntrinsics& intrinsics, const Rigid3& predicted,
                       const IcpOptions& options = {}, const std::vector<IcpAnchor>& anchors = {},
                       const IcpContour* contour = nullptr, const Rigid3* start = nullptr);

}  // namespace ihs::fusion
