#include "core/rigid3.h"

#include <cmath>

#include "core/check.h"

namespace ihs {
namespace {

// Nearest rotation in the Frobenius sense, so that products of many transforms stay rigid.
Eigen::Matrix3d Orthonormalize(const Eigen::Matrix3d& matrix) {
  return Eigen::Quaterniond(matrix).normalized().toRotationMatrix();
}

}  // namespace

Rigid3::Rigid3(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
    : rotation_(Orthonormalize(rotation)), translation_(translation) {}

Rigid3::Rigid3(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
    : rotation_(rotation.normalized().toRotationMatrix()), translation_(translation) {}

Rigid3 Rigid3::Translation(const Eigen::Vector3d& translation) {
  return Rigid3(Eigen::Matrix3d::Identity(), translation);
}

Rigid3 Rigid3::FromAxisAngle(const Eigen::Vector3d& axis, double angle_rad,
                             const Eigen::Vector3d& translation) {
  IHS_CHECK_ARG(axis.norm() > 0, "rotation axis must not be zero");
  return Rigid3(Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix(), translation);
}

Rigid3 Rigid3::FromRotationVector(const Eigen::Vector3d& rotation_vector,
                                  const Eigen::Vector3d& translation) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-12) return Translation(translation);
  return FromAxisAngle(rotation_vector / angle, angle, translation);
}

Rigid3 Rigid3::FromMatrix(const Eigen::Matrix4d& matrix, double tolerance) {
  IHS_CHECK_ARG(matrix.allFinite(), "transform matrix has non-finite entries");
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const double orthogonality =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
  const double determinant = rotation.determinant();
  IHS_CHECK_ARG(orthogonality <= tolerance && std::abs(determinant - 1.0) <= tolerance,
                "transform matrix is not rigid (|R^T R - I| = " << orthogonality << ", det R = "
                                                                << determinant << ")");
  IHS_CHECK_ARG((matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() <= tolerance,
                "transform matrix's last row is not 0 0 0 1");
  return Rigid3(rotation, matrix.topRightCorner<3, 1>());
}

Eigen::Vector3d Rigid3::RotationVector() const {
  const Eigen::AngleAxisd angle_axis(rotation_);
  return angle_axis.axis() * angle_axis.angle();
}

Eigen::Matrix4d Rigid3::ToMatrix() const {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix.topLeftCorner<3, 3>() = rotation_;
  matrix.topRightCorner<3, 1>() = translation_;
  return matrix;
}

Rigid3 Rigid3::Inverse() const {
  Rigid3 inverse;
  inverse.rotation_ = rotation_.transpose();
  inverse.translation_ = -(inverse.rotation_ * translation_);
  return inverse;
}

Rigid3 Rigid3::operator*(const Rigid3& b_from_a) const {
  Rigid3 c_from_a;
  c_from_a.rotation_ = Orthonormalize(rotation_ * b_from_a.rotation_);
  c_from_a.translation_ = rotation_ * b_from_a.translation_ + translation_;
  return c_from_a;
}

double Rigid3::RotationAngleRad() const {
  // acos of the trace is ill-conditioned near 0 and π; the quaternion form is accurate everywhere.
  const Eigen::Quaterniond q(rotation_);
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

double Rigid3::RotationAngleToRad(const Rigid3& other) const {
  return (Inverse() * other).RotationAngleRad();
}

Rigid3 Rigid3::Interpolate(const Rigid3& other, double s) const {
  const Rigid3 delta = Inverse() * other;  // this_from_other
  const Eigen::Vector3d rotation_vector = delta.RotationVector() * s;
  Rigid3 result = *this * FromRotationVector(rotation_vector, Eigen::Vector3d::Zero());
  result.translation_ = translation_ + s * (other.translation_ - translation_);
  return result;
}

}  // namespace ihs
