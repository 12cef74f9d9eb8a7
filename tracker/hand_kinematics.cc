#include "tracker/hand_kinematics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace ihs::tracker {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// exp of a rotation vector and its left Jacobian J_l(ω), with which
// exp(ω + δ) ≈ exp(J_l·δ)·exp(ω).
void RotationAndLeftJacobian(const Eigen::Vector3d& omega, Eigen::Matrix3d* rotation,
                             Eigen::Matrix3d* left_jacobian) {
  const double theta = omega.norm();
  const Eigen::Matrix3d k = Skew(omega);
  double a, b;  // J_l = I + a·[ω]× + b·[ω]×²
  if (theta < 1e-5) {
    a = 0.5 - theta * theta / 24;
    b = 1.0 / 6 - theta * theta / 120;
    *rotation = Eigen::Matrix3d::Identity() + k + 0.5 * k * k;
  } else {
    a = (1 - std::cos(theta)) / (theta * theta);
    b = (theta - std::sin(theta)) / (theta * theta * theta);
    *rotation = Eigen::AngleAxisd(theta, omega / theta).toRotationMatrix();
  }
  *left_jacobian = Eigen::Matrix3d::Identity() + a * k + b * k * k;
}

}  // namespace

PoseParameters::PoseParameters(const HandPose& pose)
    : reference_(pose.cam_from_root.rotation()), values_(6 + pose.angles_rad.size(), 0.0) {
  for (int i = 0; i < 3; ++i) values_[3 + i] = pose.cam_from_root.translation()[i];
  for (size_t k = 0; k < pose.angles_rad.size(); ++k) values_[6 + k] = pose.angles_rad[k];
}

HandPose PoseParameters::ToPose() const {
  const Eigen::Vector3d omega(values_[0], values_[1], values_[2]);
  const Eigen::Matrix3d rotation =
      omega.norm() > 0
          ? Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix() * reference_
          : reference_;
  HandPose pose;
  pose.cam_from_root = Rigid3(rotation, Eigen::Vector3d(values_[3], values_[4], values_[5]));
  pose.angles_rad.assign(values_.begin() + 6, values_.end());
  return pose;
}

PoseDerivatives::PoseDerivatives(const HandModel& model)
    : model_(model), dofs_(JointDegreesOfFreedom(model)) {
  const size_t bones = model.bones.size();
  rest_on_parent_.resize(bones);
  bone_from_model_rest_.resize(bones);
  moving_dofs_.resize(bones);
  for (size_t b = 0; b < bones; ++b) {
    bone_from_model_rest_[b] = model.model_from_bone_rest[b].Inverse();
    const int parent = model.bones[b].parent;
    if (parent >= 0) {
      rest_on_parent_[b] =
          model.model_from_bone_rest[parent].Inverse() * model.model_from_bone_rest[b];
      moving_dofs_[b] = moving_dofs_[parent];
    }
    for (size_t k = 0; k < dofs_.size(); ++k) {
      if (dofs_[k].bone == static_cast<int>(b)) moving_dofs_[b].push_back(6 + static_cast<int>(k));
    }
  }
  cam_from_bone_.resize(bones);
  axis_.resize(6 + dofs_.size());
  pivot_.resize(6 + dofs_.size());
}

void PoseDerivatives::Evaluate(const Eigen::Matrix3d& reference_rotation, const double* x) {
  Eigen::Matrix3d rotation;
  RotationAndLeftJacobian(Eigen::Vector3d(x[0], x[1], x[2]), &rotation, &left_jacobian_);
  root_translation_ = Eigen::Vector3d(x[3], x[4], x[5]);
  cam_from_bone_[0] = Rigid3(rotation * reference_rotation, root_translation_);
  size_t k = 0;
  for (size_t b = 1; b < model_.bones.size(); ++b) {
    const Rigid3 base = cam_from_bone_[model_.bones[b].parent] * rest_on_parent_[b];
    Eigen::Matrix3d accumulated = base.rotation();
    for (; k < dofs_.size() && dofs_[k].bone == static_cast<int>(b); ++k) {
      const Eigen::Vector3d axis = model_.limits[b].axes[dofs_[k].axis].normalized();
      axis_[6 + k] = accumulated * axis;
      pivot_[6 + k] = base.translation();
      accumulated = accumulated * Eigen::AngleAxisd(x[6 + k], axis).toRotationMatrix();
    }
    cam_from_bone_[b] = Rigid3(accumulated, base.translation());
  }
}

void PoseDerivatives::AccumulateJacobian(int bone, double w, const Eigen::Vector3d& moved,
                                         double* jacobian) const {
  const int n = size();
  // Root rotation: ∂(exp(ω)·z)/∂ω = −[x − t]×·J_l(ω).
  const Eigen::Matrix3d root = -w * Skew(moved - root_translation_) * left_jacobian_;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) jacobian[r * n + c] += root(r, c);
    jacobian[r * n + 3 + r] += w;
  }
  for (int index : moving_dofs_[bone]) {
    const Eigen::Vector3d d = w * axis_[index].cross(moved - pivot_[index]);
    for (int r = 0; r < 3; ++r) jacobian[r * n + index] += d[r];
  }
}

Eigen::Vector3d PoseDerivatives::SkinnedPoint(const VertexWeights& weights,
                                              const Eigen::Vector3f& rest_in_model,
                                              double* jacobian) const {
  if (jacobian) std::fill(jacobian, jacobian + 3 * size(), 0.0);
  const Eigen::Vector3d rest = rest_in_model.cast<double>();
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (const auto& [bone, weight] : weights.bones) {
    const Eigen::Vector3d moved = cam_from_bone_[bone] * (bone_from_model_rest_[bone] * rest);
    x += weight * moved;
    if (jacobian) AccumulateJacobian(bone, weight, moved, jacobian);
  }
  return x;
}

Eigen::Vector3d PoseDerivatives::BonePoint(int bone, const Eigen::Vector3d& in_bone,
                                           double* jacobian) const {
  const Eigen::Vector3d moved = cam_from_bone_[bone] * in_bone;
  if (jacobian) {
    std::fill(jacobian, jacobian + 3 * size(), 0.0);
    AccumulateJacobian(bone, 1.0, moved, jacobian);
  }
  return moved;
}

namespace {

// Adds `more` (ascending) to the ascending `columns`, keeping them ascending and unique.
void MergeColumns(const std::vector<int>& more, std::vector<int>* columns) {
  const size_t before = columns->size();
  columns->insert(columns->end(), more.begin(), more.end());
  std::inplace_merge(columns->begin(), columns->begin() + static_cast<std::ptrdiff_t>(before),
                     columns->end());
  columns->erase(std::unique(columns->begin(), columns->end()), columns->end());
}

}  // namespace

void PoseDerivatives::Columns(const VertexWeights& weights, std::vector<int>* columns) const {
  columns->assign({0, 1, 2, 3, 4, 5});
  for (const auto& [bone, weight] : weights.bones) MergeColumns(moving_dofs_[bone], columns);
}

void PoseDerivatives::Columns(int bone_a, int bone_b, std::vector<int>* columns) const {
  columns->assign({0, 1, 2, 3, 4, 5});
  MergeColumns(moving_dofs_[bone_a], columns);
  MergeColumns(moving_dofs_[bone_b], columns);
}

}  // namespace ihs::tracker
