#include "core/rigid3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/test_util.h"

namespace ihs {
namespace {

Rigid3 RandomRigid(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  const Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
  const Eigen::Vector3d translation(100 * normal(rng), 100 * normal(rng), 500 + 100 * normal(rng));
  return Rigid3::FromAxisAngle(axis, angle(rng), translation);
}

TEST(Rigid3Test, ComposesInTheBFromANamingOrder) {
  // object_from_world: rotate 90° about z; cam_from_object: shift by 10 mm along x.
  const Rigid3 object_from_world = Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), M_PI / 2);
  const Rigid3 cam_from_object = Rigid3::Translation({10, 0, 0});
  const Rigid3 cam_from_world = cam_from_object * object_from_world;
  const Eigen::Vector3d p = cam_from_world * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(p.x(), 10.0, 1e-12);
  EXPECT_NEAR(p.y(), 1.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.0, 1e-12);
}

TEST(Rigid3Test, InverseUndoesTheTransformForRandomPoses) {
  std::mt19937 rng = test::Rng(1);
  for (int trial = 0; trial < 100; ++trial) {
    const Rigid3 b_from_a = RandomRigid(rng);
    const Eigen::Vector3d x(rng() % 200 - 100.0, rng() % 200 - 100.0, rng() % 200 - 100.0);
    EXPECT_LT((b_from_a.Inverse() * (b_from_a * x) - x).norm(), 1e-9);
    const Rigid3 identity = b_from_a.Inverse() * b_from_a;
    EXPECT_LT(identity.RotationAngleRad(), 1e-9);
    EXPECT_LT(identity.translation().norm(), 1e-9);
  }
}

TEST(Rigid3Test, MatchesHomogeneousMatrixProducts) {
  std::mt19937 rng = test::Rng(2);
  const Rigid3 c_from_b = RandomRigid(rng), b_from_a = RandomRigid(rng);
  const Eigen::Matrix4d expected = c_from_b.ToMatrix() * b_from_a.ToMatrix();
  EXPECT_LT(((c_from_b * b_from_a).ToMatrix() - expected).norm(), 1e-9);
  const Rigid3 round_trip = Rigid3::FromMatrix(expected);
  EXPECT_LT((round_trip.ToMatrix() - expected).norm(), 1e-9);
}

TEST(Rigid3Test, FromMatrixRejectsNonRigidMatrices) {
  Eigen::Matrix4d scaled = Eigen::Matrix4d::Identity();
  scaled(0, 0) = 1.1;
  EXPECT_THROW(Rigid3::FromMatrix(scaled), std::invalid_argument);
  Eigen::Matrix4d mirrored = Eigen::Matrix4d::Identity();
  mirrored(2, 2) = -1;
  EXPECT_THROW(Rigid3::FromMatrix(mirrored), std::invalid_argument);
  Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
  projective(3, 0) = 0.5;
  EXPECT_THROW(Rigid3::FromMatrix(projective), std::invalid_argument);
  Eigen::Matrix4d not_finite = Eigen::Matrix4d::Identity();
  not_finite(0, 3) = NAN;
  EXPECT_THROW(Rigid3::FromMatrix(not_finite), std::invalid_argument);
}

TEST(Rigid3Test, ReportsRotationAnglesAccuratelyNearZeroAndPi) {
  for (double angle : {1e-7, 0.3, 1.0, M_PI - 1e-7, M_PI}) {
    const Rigid3 t = Rigid3::FromAxisAngle({1, 2, 3}, angle);
    EXPECT_NEAR(t.RotationAngleRad(), angle, 1e-9) << angle;
  }
  const Rigid3 a = Rigid3::FromAxisAngle({0, 0, 1}, 0.2);
  const Rigid3 b = Rigid3::FromAxisAngle({0, 0, 1}, 0.5, {3, 4, 0});
  EXPECT_NEAR(a.RotationAngleToRad(b), 0.3, 1e-12);
  EXPECT_NEAR(a.TranslationDistanceTo(b), 5.0, 1e-12);
}

TEST(Rigid3Test, RotationVectorRoundTrips) {
  const Eigen::Vector3d rotation_vector(0.1, -0.4, 0.7);
  const Rigid3 t = Rigid3::FromRotationVector(rotation_vector, {1, 2, 3});
  EXPECT_LT((t.RotationVector() - rotation_vector).norm(), 1e-12);
  EXPECT_LT(Rigid3::FromRotationVector(Eigen::Vector3d::Zero(), {1, 2, 3}).RotationAngleRad(),
            1e-15);
}

TEST(Rigid3Test, InterpolatesAlongTheGeodesicAndExtrapolates) {
  const Rigid3 a = Rigid3::FromAxisAngle({0, 1, 0}, 0.2, {0, 0, 0});
  const Rigid3 b = Rigid3::FromAxisAngle({0, 1, 0}, 0.6, {10, 0, 0});
  const Rigid3 half = a.Interpolate(b, 0.5);
  EXPECT_NEAR(half.RotationAngleRad(), 0.4, 1e-12);
  EXPECT_NEAR(half.translation().x(), 5.0, 1e-12);
  const Rigid3 next = a.Interpolate(b, 2.0);  // Constant-velocity prediction.
  EXPECT_NEAR(next.RotationAngleRad(), 1.0, 1e-12);
  EXPECT_NEAR(next.translation().x(), 20.0, 1e-12);
}

TEST(Rigid3Test, StaysOrthonormalOverManyCompositions) {
  const Rigid3 step = Rigid3::FromAxisAngle({1, 1, 0}, 2 * M_PI / 1000, {0.1, 0, 0});
  Rigid3 accumulated;
  for (int i = 0; i < 1000; ++i) accumulated = step * accumulated;
  const Eigen::Matrix3d& r = accumulated.rotation();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT(accumulated.RotationAngleRad(), 1e-9);  // A full turn.
}

}  // namespace
}  // namespace ihs
