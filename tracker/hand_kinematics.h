#pragma once
// Forward kinematics with derivatives, for fitting a hand pose by least squares. A pose is one
// parameter vector x = [ω (3), t (3), joint angles (n)]: the root's rotation is exp(ω)·R_ref with
// a reference rotation R_ref held fixed during a solve (ω stays small), its translation t (mm),
// and the angles in JointDegreesOfFreedom order (rad).

#include <Eigen/Core>
#include <vector>

#include "core/rigid3.h"
#include "tracker/hand_model.h"
#include "tracker/hand_pose.h"

namespace ihs::tracker {

/// Converts between HandPose and the parameter vector around a reference rotation.
class PoseParameters {
 public:
  /// Parameters of `pose` with R_ref = its root rotation (ω = 0).
  explicit PoseParameters(const HandPose& pose);

  const Eigen::Matrix3d& reference_rotation() const { return reference_; }
  /// The parameter vector.
  std::vector<double>& values() { return values_; }
  const std::vector<double>& values() const { return values_; }
  /// The pose these parameters describe.
  HandPose ToPose() const;

 private:
  Eigen::Matrix3d reference_;
  std::vector<double> values_;
};

/// Bone transforms and point Jacobians at one parameter vector.
class PoseDerivatives {
 public:
  explicit PoseDerivatives(const HandModel& model);

  /// Number of parameters (6 + degrees of freedom).
  int size() const { return 6 + static_cast<int>(dofs_.size()); }
  /// Evaluates the kinematics at `x` (size() values) around `reference_rotation`.
  void Evaluate(const Eigen::Matrix3d& reference_rotation, const double* x);

  /// cam_from_bone of every bone at the last Evaluate.
  const std::vector<Rigid3>& cam_from_bone() const { return cam_from_bone_; }

  /// The skinned position (camera frame) of a rest-mesh point `rest_in_model` with skinning
  /// `weights`; when `jacobian` is given, also ∂x/∂params, row-major 3 × size().
  Eigen::Vector3d SkinnedPoint(const VertexWeights& weights, const Eigen::Vector3f& rest_in_model,
                               double* jacobian) const;
  /// A point fixed in bone `bone`'s frame, in the camera frame; optionally with its Jacobian.
  Eigen::Vector3d BonePoint(int bone, const Eigen::Vector3d& in_bone, double* jacobian) const;

  /// The parameters that move a point of `bones` (ascending, into `columns`): the root's six and
  /// the degrees of freedom of each bone and its ancestors. Its Jacobian is zero elsewhere.
  void Columns(const VertexWeights& weights, std::vector<int>* columns) const;
  void Columns(int bone_a, int bone_b, std::vector<int>* columns) const;

 private:
  // Adds w·∂(cam_from_bone[bone]·p)/∂params to `jacobian`, given the moved point `moved`.
  void AccumulateJacobian(int bone, double w, const Eigen::Vector3d& moved, double* jacobian) const;

  const HandModel& model_;
  std::vector<DegreeOfFreedom> dofs_;
  std::vector<Rigid3> rest_on_parent_;
  std::vector<Rigid3> bone_from_model_rest_;
  // Parameter indices (≥ 6) of the degrees of freedom that move each bone: its own and its
  // ancestors'.
  std::vector<std::vector<int>> moving_dofs_;
  std::vector<Rigid3> cam_from_bone_;
  std::vector<Eigen::Vector3d> axis_;   // World axis per parameter index (≥ 6).
  std::vector<Eigen::Vector3d> pivot_;  // World pivot per parameter index (≥ 6).
  Eigen::Vector3d root_translation_;
  Eigen::Matrix3d left_jacobian_;  // J_l(ω) of the root rotation.
};

}  // namespace ihs::tracker
