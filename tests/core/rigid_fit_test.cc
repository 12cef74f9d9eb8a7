#include "core/rigid_fit.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/test_util.h"

namespace ihs {
namespace {

TEST(RigidFitTest, RecoversAKnownTransformAndIgnoresZeroWeightOutliers) {
  std::mt19937 rng = test::Rng();
  std::uniform_real_distribution<double> unit(-1, 1);
  const Rigid3 b_from_a = Rigid3::FromAxisAngle({0.3, -1, 0.5}, 1.1, {40, -25, 610});
  std::vector<Eigen::Vector3d> from, to;
  std::vector<double> weights;
  for (int i = 0; i < 50; ++i) {
    from.emplace_back(60 * unit(rng), 60 * unit(rng), 60 * unit(rng));
    to.push_back(b_from_a * from.back());
    weights.push_back(1 + std::abs(unit(rng)));
  }
  EXPECT_LT((FitRigidTransform(from, to).ToMatrix() - b_from_a.ToMatrix()).norm(), 1e-9);
  // Wrong pairs with no weight change nothing; with weight they would.
  for (int i = 0; i < 10; ++i) {
    from.emplace_back(60 * unit(rng), 60 * unit(rng), 60 * unit(rng));
    to.emplace_back(60 * unit(rng), 60 * unit(rng), 600 + 60 * unit(rng));
    weights.push_back(0);
  }
  EXPECT_LT((FitRigidTransform(from, to, weights).ToMatrix() - b_from_a.ToMatrix()).norm(), 1e-9);
  EXPECT_GT((FitRigidTransform(from, to).ToMatrix() - b_from_a.ToMatrix()).norm(), 1e-3);
}

TEST(RigidFitTest, RefusesMismatchedOrWeightlessInput) {
  const std::vector<Eigen::Vector3d> three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_THROW(FitRigidTransform(three, {{0, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(FitRigidTransform({}, {}), std::invalid_argument);
  EXPECT_THROW(FitRigidTransform(three, three, {1, 1}), std::invalid_argument);
  EXPECT_THROW(FitRigidTransform(three, three, {0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(FitRigidTransform(three, three, {1, -1, 1}), std::invalid_argument);
}

}  // namespace
}  // namespace ihs
