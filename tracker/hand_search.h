#pragma once
// Where a hand might be, from nothing but its points: the hand-tracker's global search. Many
// whole-hand orientations (spread evenly over all rotations, and the hand cloud's principal
// axes each way round) of a few articulations are each moved rigidly onto the hand points and
// ranked by how well the depth image agrees with them; the best few go on to the articulated
// fit (HandTracker). The articulated fit only finds the pose near where it starts: started
// from the cloud's principal axes alone, grasping hands on the generator's scripted motions
// were 20–76° from every hypothesis and were fitted 35–100 mm off.

#include <Eigen/Core>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "tracker/grasp_side.h"
#include "tracker/hand_model.h"
#include "tracker/hand_pose.h"

namespace ihs::tracker {

/// Options of the search (defaults: neighbouring orientations about 40–45° apart).
struct HandSearchOptions {
  /// Directions of the hand's long axis (spread evenly over the sphere) and turns about it per
  /// direction: directions × rolls orientations per articulation, besides the principal axes'.
  int directions = 26;
  int rolls = 8;
  /// Rigid ICP iterations placing each orientation on the hand points.
  int placement_iterations = 6;
  /// Model and data points used to place and score a hypothesis, at most.
  int sample_points = 250;
  /// A model point's distance to the nearest hand point counts up to this, mm (and the other
  /// way round): a hypothesis is scored by the mean of both.
  double score_cap_mm = 30.0;
  /// Where an object is seen in the hand (GraspSide), starts that hold it in the palm as well:
  /// the palm facing the object's middle from the hand points' side (and tilted by
  /// grasp_tilt_deg four ways), turned about its normal in grasp_rolls steps (0: none).
  int grasp_rolls = 12;
  double grasp_tilt_deg = 25.0;
  /// Threads that place and score the starts (0: one per core). A search stalls the tracker
  /// for 0.6 s on one core, and meanwhile the pipeline's fusion thread has nothing to fuse; the
  /// result is the same whatever the number.
  int threads = 0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// A hypothesis and its score (mean capped distance, mm; lower is better).
struct SearchHypothesis {
  HandPose pose;
  double score = 0;
};

/// The global search for one model and camera.
class HandSearch {
 public:
  HandSearch(const HandModel& model, const CameraIntrinsics& intrinsics,
             HandSearchOptions options = {});

  /// The `count` best placed hypotheses (best first) for `hand_points` (camera frame, mm) seen
  /// in `frame`, over every articulation in `articulations` and `tracked` in every orientation
  /// (their root poses ignored); each of `tracked` (poses the tracker held) is also placed from
  /// its own root pose. With `side`, a hypothesis whose palm faces away from the held object
  /// scores worse by GraspSide::Penalty (`right_hand`: the model's side).
  std::vector<SearchHypothesis> Best(const std::vector<Eigen::Vector3f>& hand_points,
                                     const Frame& frame, const std::vector<HandPose>& articulations,
                                     const std::vector<HandPose>& tracked, int count,
                                     const GraspSide* side = nullptr, bool right_hand = true) const;

  const HandSearchOptions& options() const { return options_; }

 private:
  const HandModel& model_;
  const CameraIntrinsics intrinsics_;
  const HandSearchOptions options_;
  std::vector<Eigen::Matrix3d> orientations_;
};

/// The joint angles of `model` with every finger flexed by `fraction` of its flexion limit
/// toward the palm (root pose: identity).
HandPose CurledHand(const HandModel& model, double fraction);

/// `pose` turned over: its root turned 180° about the hand's long axis (the wrist to the middle
/// finger's knuckle) through the palm's middle (the wrist and the four knuckles' centroid), so
/// the palm faces where the back did and the thumb lies where the little finger did; the
/// articulation is kept. The ambiguity a depth fit can tie on (docs/tracker.md).
HandPose TurnedOver(const HandModel& model, const HandPose& pose);

/// `pose` with the thumb's first joint (the metacarpal's, every active axis) set to each of a
/// few angles across its range (a sixth of the range in from each limit, and the middle): the
/// thumb's placements a fit from another one does not reach (it opposes the fingers round a held
/// object, lies along the index, or crosses the palm): 3^n of them for n active axes (27 on
/// the procedural template), the rest of the pose kept; none where the model has no thumb.
std::vector<HandPose> ThumbVariants(const HandModel& model, const HandPose& pose);

/// Rigid starts (cam_from_root) for an articulation whose palm (in its root's frame) is `palm`
/// that hold an object in the palm: the palm's normal (toward the palm, `right_hand` the
/// model's side) points at `object` (the held object's middle) from the side of `hand` (the hand
/// points' centroid), and tilted by options.grasp_tilt_deg four ways, each turned about the
/// normal in options.grasp_rolls steps; the palm's middle as far from `object` as `hand` is.
std::vector<Rigid3> GraspStarts(const PalmAxes& palm, bool right_hand,
                                const Eigen::Vector3d& object, const Eigen::Vector3d& hand,
                                const HandSearchOptions& options);

}  // namespace ihs::tracker
