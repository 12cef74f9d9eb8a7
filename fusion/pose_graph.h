#pragma once
// A pose graph over views of one rigid object: each node is a view's pose (cam_from_object),
// each edge a measured motion between two views' cameras (cam_to_from_cam_from). Solving it
// spreads what the edges disagree on — a full turn's accumulated drift, once an edge ties its
// end to its start — over the views, the way the edges allow (Lu & Milios 1997; Ceres' pose
// graph example solves the same problem on 2-D and 3-D maps).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/rigid3.h"

namespace ihs::fusion {

/// One measured motion: the camera of view `to` from the camera of view `from`.
struct PoseGraphEdge {
  int from = 0;
  int to = 0;
  Rigid3 to_from_from;
  /// Relative weight of its residual (least squares: where edges disagree, an edge of weight
  /// w takes 1/w² as much of the disagreement as one of weight 1).
  double weight = 1.0;
  /// The motion measured everything but the object's spin about an axis well (a ball or a
  /// bottle turned by the hand: its shape fixed the rest): with a SpinAxis given to the solve,
  /// the edge holds that axis at `weight` and the rest at PoseGraphOptions::spin_weight of it.
  bool spin_free = false;
};

/// A line of the object frame (mm) its spin is about: a bottle's axis, a line through a ball's
/// centre.
struct SpinAxis {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

/// Options of the solve (defaults: a hand-held object a few centimetres across).
struct PoseGraphOptions {
  /// An edge's disagreement is measured as how far it moves the object frame's origin and three
  /// points this far from it along its axes (mm): turns and shifts weigh as they move the
  /// object's surface.
  double lever_mm = 40.0;
  /// A `spin_free` edge's hold on the spin about the SpinAxis, against its hold on the axis:
  /// small, so that a loop's turn goes into spins about the axis, spread evenly over the
  /// edges (tens of degrees after a turn the hand carried), and not into shifts and tilts
  /// that would smear a re-fused model.
  double spin_weight = 0.05;
  int max_iterations = 50;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The poses (cam_from_object, one per node) that best agree with `edges`, node 0 held where it
/// is (it fixes the object frame). Nodes no edge reaches keep their pose. With `spin_axis`, the
/// `spin_free` edges hold the spin about it loosely (PoseGraphOptions::spin_weight).
std::vector<Rigid3> SolvePoseGraph(const std::vector<Rigid3>& cam_from_object,
                                   const std::vector<PoseGraphEdge>& edges,
                                   const PoseGraphOptions& options = {},
                                   const std::optional<SpinAxis>& spin_axis = std::nullopt);

/// The line a correction of the object frame turns about (its screw axis) where it turns by
/// at least `min_deg`; none for less (the line is then ill-defined).
std::optional<SpinAxis> ScrewAxis(const Rigid3& correction, double min_deg);

/// How far `a` and `b` (two poses of the object, cam_from_object) put the object's points at
/// `lever_mm` from its origin apart, at most (mm).
double PoseDistanceMm(const Rigid3& a, const Rigid3& b, double lever_mm);

}  // namespace ihs::fusion
