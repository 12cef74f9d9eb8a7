#pragma once
// Rigid transforms named by the frames they connect: `b_from_a` maps coordinates in frame a to
// coordinates in frame b, x_b = R·x_a + t. Compose as c_from_a = c_from_b * b_from_a.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ihs {

/// A rotation and a translation (mm). Name values `b_from_a`; never a bare `pose`.
class Rigid3 {
 public:
  /// The identity transform.
  Rigid3() : rotation_(Eigen::Matrix3d::Identity()), translation_(Eigen::Vector3d::Zero()) {}
  /// From a rotation matrix (must be orthonormal with determinant +1; re-orthonormalised) and a
  /// translation in mm.
  Rigid3(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);
  /// From a unit quaternion (normalised here) and a translation in mm.
  Rigid3(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);

  /// The identity transform.
  static Rigid3 Identity() { return Rigid3(); }
  /// A pure translation (mm).
  static Rigid3 Translation(const Eigen::Vector3d& translation);
  /// A rotation of `angle_rad` about `axis` (need not be unit length), then a translation.
  static Rigid3 FromAxisAngle(const Eigen::Vector3d& axis, double angle_rad,
                              const Eigen::Vector3d& translation = Eigen::Vector3d::Zero());
  /// From a rotation vector (axis · angle in rad) and a translation.
  static Rigid3 FromRotationVector(const Eigen::Vector3d& rotation_vector,
                                   const Eigen::Vector3d& translation);
  /// From a homogeneous 4×4 matrix; throws std::invalid_argument if the upper-left 3×3 block is
  /// not a rotation within `tolerance` (‖RᵀR − I‖ and |det R − 1|) or the last row is not 0 0 0 1.
  static Rigid3 FromMatrix(const Eigen::Matrix4d& matrix, double tolerance = 1e-3);

  /// Rotation matrix R.
  const Eigen::Matrix3d& rotation() const { return rotation_; }
  /// Translation t, mm.
  const Eigen::Vector3d& translation() const { return translation_; }
  /// Rotation as a unit quaternion.
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(rotation_); }
  /// Rotation as a rotation vector (axis · angle, rad).
  Eigen::Vector3d RotationVector() const;
  /// Homogeneous 4×4 matrix.
  Eigen::Matrix4d ToMatrix() const;

  /// a_from_b for this b_from_a.
  Rigid3 Inverse() const;
  /// c_from_a = (*this = c_from_b) * b_from_a.
  Rigid3 operator*(const Rigid3& b_from_a) const;
  /// Maps a point from frame a to frame b: R·x + t.
  Eigen::Vector3d operator*(const Eigen::Vector3d& point_in_a) const {
    return rotation_ * point_in_a + translation_;
  }
  /// Maps a point from frame a to frame b (single precision).
  Eigen::Vector3f operator*(const Eigen::Vector3f& point_in_a) const {
    return (rotation_ * point_in_a.cast<double>() + translation_).cast<float>();
  }
  /// Rotates a direction (no translation).
  Eigen::Vector3d RotateVector(const Eigen::Vector3d& direction_in_a) const {
    return rotation_ * direction_in_a;
  }

  /// Rotation angle of this transform, rad, in [0, π].
  double RotationAngleRad() const;
  /// Angle of the rotation between this and `other` (rad) — `this⁻¹·other`.
  double RotationAngleToRad(const Rigid3& other) const;
  /// Distance between the translations of this and `other`, mm.
  double TranslationDistanceTo(const Rigid3& other) const {
    return (translation_ - other.translation_).norm();
  }
  /// Interpolates between this (s = 0) and `other` (s = 1): slerp of the rotation, linear
  /// translation. s outside [0, 1] extrapolates.
  Rigid3 Interpolate(const Rigid3& other, double s) const;

 private:
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d translation_;
};

}  // namespace ihs
