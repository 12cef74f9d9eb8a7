#pragma once
// Which side of the hand a held object is on. A hand holding something has it on its palm's
// side: fingers flex toward the palm, and whatever they and the thumb hold lies there (a power
// grasp, a pinch, a ball cupped from below). A depth fit alone cannot tell a hand seen from
// its back from one seen from its palm where the fingers hide behind the object, and the
// search's hypotheses tie on such views (issue 32: on the generated grasps of
// tools/bench_hand_init.sh every true pose has its palm toward the object, cosine 0.53–0.89
// between its normal and the direction to the object's middle, while the wrong fits kept
// there lay at −0.67–0.98). GraspSide turns that into a penalty in the tracker's scores: a pose
// whose palm faces away from the object seen in its hand explains the frame worse. So does one
// whose thumb is not across the object from its fingers: a hand holds what it holds between
// them, and a thumb hidden behind the object, which depth does not show, slides to the fingers'
// side (docs/tracker.md).

#include <Eigen/Core>
#include <optional>

#include "tracker/hand_model.h"
#include "tracker/hand_pose.h"
#include "tracker/segmentation.h"

namespace ihs::tracker {

/// Options of the grasp-side prior (weight 0: off).
struct GraspSideOptions {
  /// Penalty per unit of cosine below min_cosine, in the tracker's score units (mm of mean
  /// distance; a twentieth of the hand's points left unexplained is 1).
  double weight = 10.0;
  /// Cosine between the palm's normal and the direction from the palm's middle to the object's
  /// middle below which a pose is penalised.
  double min_cosine = 0.2;
  /// Object points count when they lie within this distance of the hand points' centroid, mm
  /// (the part of a held object by the hand, not the table beyond it).
  double near_hand_mm = 120.0;
  /// Fewer object points than this near the hand: no object seen, no prior.
  int min_object_points = 100;
  /// Penalty per unit of cosine above max_opposition_cosine between the directions from the
  /// object's middle to the thumb's tip and to the fingertips' centroid (a hand holding
  /// something holds it between its thumb and its fingers: −1 straight across). Off (0) by
  /// default, with TrackerOptions::thumb_check: at 10 the hand's fits flip less, but the scans
  /// of 22 full turns followed less of them (docs/tracker.md).
  double opposition_weight = 0.0;
  double max_opposition_cosine = 0.2;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The object held in one frame, and how a pose's palm faces it.
class GraspSide {
 public:
  /// The object seen by the hand in `segmentation`, or nothing when too little of it is seen
  /// (or the prior is off). Its middle: the near object points' centroid moved away from the
  /// camera by 0.7 of their spread across the ray (a ball's visible cap has its centroid half a
  /// radius in front of the ball's centre, its image's RMS radius is the radius over √2).
  static std::optional<GraspSide> Of(const Segmentation& segmentation,
                                     const GraspSideOptions& options);

  /// The object's estimated middle (camera frame, mm).
  const Eigen::Vector3d& centre() const { return centre_; }

  /// The cosine between the palm's normal (toward the palm, for either hand) and the direction
  /// from the palm's middle to the object's middle. `right_hand`: the model's side.
  double Cosine(const PalmAxes& palm, bool right_hand) const;

  /// The penalty of a palm so placed: weight × how far its cosine lies below min_cosine.
  double Penalty(const PalmAxes& palm, bool right_hand) const;

  /// The cosine between the directions from the object's middle to the thumb's tip and to the
  /// other fingertips' centroid, of `joints` (HandModel::JointPositions) of `model`; 1 for a
  /// model without a thumb.
  double Opposition(const HandModel& model, const std::vector<Eigen::Vector3d>& joints) const;

  /// Penalty of `pose` of `model`: its palm's (from its joints) and its thumb's opposition.
  double Penalty(const HandModel& model, const HandPose& pose, bool right_hand) const;

 private:
  GraspSide(const Eigen::Vector3d& centre, const GraspSideOptions& options)
      : centre_(centre), options_(options) {}
  Eigen::Vector3d centre_;
  GraspSideOptions options_;
};

}  // namespace ihs::tracker
