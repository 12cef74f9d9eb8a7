// The k-d tree's nearest-neighbour queries against brute force, the bounded query included.

#include "core/point_kd_tree.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

namespace ihs {
namespace {

TEST(PointKdTreeTest, NearestAndNearestWithinAgreeWithBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coordinate(-100, 100);
  std::vector<Eigen::Vector3f> points(1500);
  for (Eigen::Vector3f& p : points) p = {coordinate(rng), coordinate(rng), 0.2f * coordinate(rng)};
  const PointKdTree tree(points);
  int within = 0, beyond = 0;
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector3f query(1.5f * coordinate(rng), 1.5f * coordinate(rng), coordinate(rng));
    int best = -1;
    float best_d2 = std::numeric_limits<float>::max();
    for (size_t i = 0; i < points.size(); ++i) {
      const float d2 = (points[i] - query).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = static_cast<int>(i);
    }
    float d2 = -1;
    ASSERT_EQ(tree.Nearest(query, &d2), best);
    EXPECT_FLOAT_EQ(d2, best_d2);
    const float bound = 15.0f * 15.0f;
    float bounded_d2 = -1;
    const int bounded = tree.NearestWithin(query, bound, &bounded_d2);
    if (best_d2 < bound) {
      ++within;
      EXPECT_EQ(bounded, best);
      EXPECT_FLOAT_EQ(bounded_d2, best_d2);
    } else {
      ++beyond;
      EXPECT_EQ(bounded, -1);
      EXPECT_EQ(bounded_d2, -1.0f);  // Left as it was.
    }
  }
  EXPECT_GT(within, 200);  // Both kinds of query were asked.
  EXPECT_GT(beyond, 200);
}

TEST(PointKdTreeTest, AnEmptyTreeHasNoNearestPoint) {
  const PointKdTree tree({});
  float d2 = -1;
  EXPECT_EQ(tree.Nearest(Eigen::Vector3f::Zero(), &d2), -1);
  EXPECT_EQ(tree.NearestWithin(Eigen::Vector3f::Zero(), 100.0f, &d2), -1);
  EXPECT_EQ(tree.CountWithin(Eigen::Vector3f::Zero(), 10.0f), 0);
}

}  // namespace
}  // namespace ihs
