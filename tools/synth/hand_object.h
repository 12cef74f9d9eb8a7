#pragma once
// Where a posed hand meets an object: the distance of each fingertip (distal segment) to the
// object's surface, which fingertips touch it, and how deep any part of the hand penetrates it.
// The generator uses it to close fingers onto objects, to place objects in recorded motions and
// to write and check the ground-truth contacts.

#include <vector>

#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "tools/synth/object_shape.h"
#include "tracker/hand_model.h"

namespace ihs::synth {

/// One fingertip against the object.
struct FingertipContact {
  /// Smallest signed distance of the fingertip's skin vertices to the surface, mm (negative:
  /// pressed into it).
  double distance_mm = 0;
  /// distance_mm ≤ the touch threshold.
  bool touching = false;
};

/// A hand pose against the object.
struct HandObjectContact {
  /// One entry per fingertip, in HandModel::EndEffectors order (pinky … index, thumb).
  std::vector<FingertipContact> fingertips;
  /// Deepest hand skin vertex inside the object, mm (0 when none is inside).
  double max_penetration_mm = 0;

  /// Number of touching fingertips.
  int TouchingCount() const;
};

/// The skin vertices of each fingertip of a hand model, for measuring contacts quickly.
class HandObjectGeometry {
 public:
  /// A vertex belongs to a fingertip when its largest skinning weight is on that end-effector.
  explicit HandObjectGeometry(const tracker::HandModel& hand);

  /// End-effector bones, in HandModel::EndEffectors order.
  const std::vector<int>& fingertip_bones() const { return fingertip_bones_; }
  /// Skin vertex indices of each fingertip.
  const std::vector<std::vector<int>>& fingertip_vertices() const { return fingertip_vertices_; }

  /// Measures `posed_hand` (camera frame, the model's vertex order) against `object` placed by
  /// `cam_from_object`; a fingertip touches when it is within `touch_mm` of the surface.
  HandObjectContact Measure(const TriangleMesh& posed_hand, const ObjectShape& object,
                            const Rigid3& cam_from_object, double touch_mm) const;

 private:
  std::vector<int> fingertip_bones_;
  std::vector<std::vector<int>> fingertip_vertices_;
};

/// Signed distance of `point_in_cam` to `object` placed by `cam_from_object`, skipping the exact
/// computation (returning a lower bound > `far_mm`) for points clearly farther than `far_mm`.
double SignedDistanceInCamera(const ObjectShape& object, const Rigid3& object_from_cam,
                              const Eigen::Vector3d& point_in_cam, double far_mm);

}  // namespace ihs::synth
