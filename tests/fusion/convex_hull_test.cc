// The convex hull as planes: signed distances right inside and out, every point inside, and
// the envelope of a revolution holding the points turned by any angle.

#include "fusion/convex_hull.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

namespace ihs::fusion {
namespace {

TEST(ConvexHullTest, ABoxsHullHasItsSixFacesAndTheirDistances) {
  // A 40 × 30 × 20 mm box's surface, sampled with noise far below the merge tolerance.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1, 1);
  const Eigen::Vector3f half(20, 15, 10);
  std::vector<Eigen::Vector3f> points;
  for (int n = 0; n < 6000; ++n) {
    Eigen::Vector3f p(unit(rng) * half.x(), unit(rng) * half.y(), unit(rng) * half.z());
    const int axis = n % 3;
    p[axis] = (n / 3) % 2 ? half[axis] : -half[axis];
    for (int k = 0; k < 3; ++k) p[k] += 0.01f * unit(rng);
    points.push_back(p);
  }
  const ConvexHull hull = ConvexHull::Of(points, 0.25);
  ASSERT_FALSE(hull.Empty());
  // The six sides, and a few bevels where the samples stop short of the edges, merged with
  // the sides they lie within 0.25 mm of: the sides' distances are right within that.
  EXPECT_GE(hull.planes(), 6);
  EXPECT_LE(hull.planes(), 14);
  for (const auto& p : points) ASSERT_LE(hull.SignedDistance(p, 5), 1e-4f);
  EXPECT_NEAR(hull.SignedDistance({0, 0, 0}, 50), -10.0f, 0.25f);  // The nearest face's.
  EXPECT_NEAR(hull.SignedDistance({0, 0, 13}, 50), 3.0f, 0.25f);   // Above the top.
  EXPECT_NEAR(hull.SignedDistance({0, 0, 13}, 2), 2.0f, 1e-6f);    // Clamped.
  EXPECT_NEAR(hull.SignedDistance({0, 0, 0}, 4), -4.0f, 1e-6f);    // Clamped inside too.
}

TEST(ConvexHullTest, TheRevolvedEnvelopeHoldsThePointsTurnedByAnyAngle) {
  // Points on one side of an axis through (5, -3, 2) along (1, 1, 1) (a third of a bottle seen).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> height(-40, 40), angle(0, 2 * M_PI / 3), radius(10, 30),
      any(0, 2 * M_PI);
  const Eigen::Vector3d centre(5, -3, 2), axis = Eigen::Vector3d(1, 1, 1).normalized();
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  std::vector<Eigen::Vector3f> points;
  for (int n = 0; n < 3000; ++n) {
    const double a = angle(rng), r = radius(rng);
    points.push_back(
        (centre + height(rng) * axis + r * (std::cos(a) * u + std::sin(a) * v)).cast<float>());
  }
  const ConvexHull plain = ConvexHull::Of(points, 0.25);
  const ConvexHull revolved = ConvexHull::Of(RevolvedEnvelope(points, centre, axis, 2.0, 64), 0.25);
  ASSERT_FALSE(revolved.Empty());
  int outside_plain = 0;
  for (const auto& p : points) {
    const Eigen::AngleAxisd turn(any(rng), axis);
    const Eigen::Vector3f turned = (centre + turn * (p.cast<double>() - centre)).cast<float>();
    ASSERT_LE(revolved.SignedDistance(turned, 5), 1e-3f) << turned.transpose();
    outside_plain += plain.SignedDistance(turned, 5) > 1;
  }
  EXPECT_GT(outside_plain, 1000);  // The plain hull holds only the side seen.
  // No wider than the widest point turned (30 mm) and the circumscribed 64-gon (0.1 %) allow.
  const Eigen::Vector3d beyond = centre + 30.2 * u;
  EXPECT_GT(revolved.SignedDistance(beyond.cast<float>(), 5), 0.0f);
}

}  // namespace
}  // namespace ihs::fusion
